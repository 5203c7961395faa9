// The seam between the trajectory server and a device: which joints it has, what they can reach
// and how one frame sets them.
#pragma once

#include "serial_robot_driver/device/body_controller.h"
#include "serial_robot_driver/ros/trajectory_server.h"

namespace serial_robot_driver::ros_layer {

/// The body's joints (~body/joint_names) and their reach; a write is one sync-write frame through
/// BodyController::sendJointCommand (ticks rounded as joint_commands rounds them). `controller`
/// must outlive the result.
TrajectoryJoints bodyTrajectoryJoints(device::BodyController& controller);

}  // namespace serial_robot_driver::ros_layer
