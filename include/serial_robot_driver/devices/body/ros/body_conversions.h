// The body's telemetry as ROS messages: the core's readings (devices/body/body_readings.h) copied
// into JointState and Imu, and the raw frame into FootPressure and Telemetry. No node, no I/O, so
// they are unit-tested without a roscore.
#pragma once

#include <ros/time.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <serial_robot_driver/FootPressure.h>
#include <serial_robot_driver/Telemetry.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_device.h"
#include "serial_robot_driver/devices/body/body_readings.h"

namespace serial_robot_driver::devices::body::ros {

using body::imuYaw;
using body::makeBodyJoints;

/// jointReadings() stamped: positions (rad) and velocities (rad/s, empty when unknown).
sensor_msgs::JointState toJointState(const Telemetry& telemetry,
                                     const std::vector<BodyJoint>& joints,
                                     const ::ros::Time& stamp);
/// The same from readings already converted.
sensor_msgs::JointState toJointState(const JointReadings& readings, const ::ros::Time& stamp);
/// The same into `msg` (every field that toJointState() sets), reusing its vectors' capacity.
void fillJointState(const JointReadings& readings, const ::ros::Time& stamp,
                    sensor_msgs::JointState* msg);
/// fillJointState() but for the names: for a message that still holds `readings.names`.
void fillJointStateValues(const JointReadings& readings, const ::ros::Time& stamp,
                          sensor_msgs::JointState* msg);

/// REP-145 IMU message: imuReading() (the bias subtracted), with diagonal covariances
/// from `params`. A negative orientation_variance marks the orientation as unknown
/// (orientation_covariance[0] = -1).
sensor_msgs::Imu toImu(const Telemetry& telemetry, const ImuParams& params,
                       const ::ros::Time& stamp, const std::array<double, 3>& gyro_bias = {});
/// toImu() of a reading already converted, into `msg` (every field), reusing its frame_id's buffer.
void fillImu(const ImuReading& reading, const ImuParams& params, const ::ros::Time& stamp,
             sensor_msgs::Imu* msg);

/// The 8 raw foot readings, or nothing when the frame did not carry the foot block.
std::optional<serial_robot_driver::FootPressure> toFootPressure(const Telemetry& telemetry,
                                                                const ::ros::Time& stamp,
                                                                const std::string& frame_id = "");

/// A joint command taken out of a JointState (only name and position matter).
JointCommand fromJointState(const sensor_msgs::JointState& msg);

/// The whole frame in raw units (for rosbag). `joints` give the servo ids in frame order.
serial_robot_driver::Telemetry toTelemetryMsg(const Telemetry& telemetry,
                                              const std::vector<BodyJoint>& joints,
                                              const ::ros::Time& stamp);

}  // namespace serial_robot_driver::devices::body::ros
