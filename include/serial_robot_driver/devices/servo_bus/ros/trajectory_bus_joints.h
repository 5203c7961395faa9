// The UART bus servos used as joints on the ROS side: each polled angle as a JointState. What the
// joints are, and how they move and stop, is ROS-free (devices/servo_bus/bus_trajectory_joints.h).
#pragma once

#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include <cstdint>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"
#include "serial_robot_driver/ros/trajectory_server.h"  // the server the bus joints report to

namespace serial_robot_driver::devices::servo_bus::ros {

/// A polled servo's joint position (busJointPosition()) stamped as a JointState.
sensor_msgs::JointState busJointState(const JointPosition& measured, const ::ros::Time& stamp);
/// The same for servo `id` at `angle_deg`.
sensor_msgs::JointState busJointState(const std::vector<trajectory::BusJoint>& joints, uint8_t id,
                                      double angle_deg, const ::ros::Time& stamp);

}  // namespace serial_robot_driver::devices::servo_bus::ros
