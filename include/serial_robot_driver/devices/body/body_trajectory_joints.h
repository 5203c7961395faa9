// The body's joints as the trajectory executor sees them (trajectory/joint_groups.h): streamed,
// one sync-write frame per loop tick.
#pragma once

#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/trajectory/joint_groups.h"

namespace serial_robot_driver::devices::body {

using trajectory::TrajectoryJoints;

/// The body's joints (~body/joint_names) and their reach; a write is one sync-write frame through
/// BodyController::sendJointCommand (ticks rounded as joint_commands rounds them). `controller`
/// must outlive the result.
TrajectoryJoints bodyTrajectoryJoints(BodyController& controller);

}  // namespace serial_robot_driver::devices::body
