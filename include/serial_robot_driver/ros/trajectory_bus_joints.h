// The UART bus servos used as joints (~servo_bus/joint_ids, joint_names, joint_zero_deg,
// joint_directions) on the ROS side: built from the node's parameters, and each polled angle as a
// joint measurement. How they move and stop is ROS-free (trajectory/joint_groups.h).
#pragma once

#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include <cstdint>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/trajectory_server.h"  // the server the bus joints report to
#include "serial_robot_driver/trajectory/bus_joint.h"
#include "serial_robot_driver/trajectory/joint_groups.h"

namespace serial_robot_driver::ros_layer {

using params::ServoBusParams;
using trajectory::busStateTimeout;
using trajectory::busTrajectoryJoints;
using trajectory::findBusJoint;
using trajectory::QueueServoMove;
using trajectory::StopServo;

/// The bus servos named as joints, from validated parameters (empty zero / direction lists: 0 / 1).
std::vector<trajectory::BusJoint> makeBusJoints(const ServoBusParams& params);

/// One polled angle as a joint measurement: the joint's name and position (rad) where `id` is a
/// joint, else servo_<id> and the servo's angle in rad.
sensor_msgs::JointState busJointState(const std::vector<trajectory::BusJoint>& joints, uint8_t id,
                                      double angle_deg, const ros::Time& stamp);

}  // namespace serial_robot_driver::ros_layer
