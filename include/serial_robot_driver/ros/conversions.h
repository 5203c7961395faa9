// Pure conversions between the ROS-free device structs and ROS messages: no node, no I/O, so they
// are unit-tested without a roscore.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <geometry_msgs/Quaternion.h>
#include <ros/time.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <serial_robot_driver/FootPressure.h>
#include <serial_robot_driver/Telemetry.h>

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/device/status_report.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

using params::AxisMap;
using params::BodyParams;
using params::ImuParams;
using params::parseAxisMap;

/// The ROS time at which a steady_clock event happened: `ros_now` minus how long ago it was
/// (`steady_now` - `event`). Saturates at ros::Time(0) instead of going negative.
ros::Time toRosTime(std::chrono::steady_clock::time_point event, const ros::Time& ros_now,
                    std::chrono::steady_clock::time_point steady_now);

/// The same, against the current ros::Time::now() and steady_clock::now().
ros::Time toRosTime(std::chrono::steady_clock::time_point event);

/// Header stamps of frames from their arrival time in the core (steady clock).
/// Live: toRosTime(), with the last conversion remembered per thread, so the users of one chunk
/// (its wire capture and the frames it completes, all on the port's reader thread) give it the
/// very same stamp. Replaying (params.replay_timeline set): the recorded stamp the arrival stands
/// for on the replay's timeline, exactly, so a replay publishes the recorded stamps.
class ArrivalStamps {
 public:
  explicit ArrivalStamps(const DriverParams& params) : replay_timeline_(params.replay_timeline) {}
  ros::Time operator()(std::chrono::steady_clock::time_point arrival) const;

 private:
  std::shared_ptr<const transport::ReplayPacing> replay_timeline_;
};

/// The joints configured from ~body (servo_ids, joint_names, zero_ticks, directions,
/// ticks_per_revolution, velocity_scale), in frame order. Assumes validated parameters.
std::vector<device::BodyJoint> makeBodyJoints(const BodyParams& params);

/// Orientation quaternion from attitude angles in rad, applied as yaw (Z) * pitch (Y) * roll (X).
geometry_msgs::Quaternion quaternionFromRollPitchYaw(double roll, double pitch, double yaw);

/// The signed permutation matrix of ~imu/axis_map (v_imu = M v_sensor); identity for a map that
/// does not parse (validate() refuses those at start-up).
Eigen::Matrix3d axisMapMatrix(const std::vector<std::string>& axis_map);

/// Joint positions (rad) and velocities (rad/s) of every configured joint. Joints beyond the
/// frame's servo_count are left out (cannot happen when the frame was decoded for these joints).
sensor_msgs::JointState toJointState(const protocol::body::Telemetry& telemetry,
                                     const std::vector<device::BodyJoint>& joints,
                                     const ros::Time& stamp);

/// REP-145 IMU message: accel (m/s^2) and gyro (rad/s) scaled from raw LSB, orientation from the
/// attitude angles, diagonal covariances from `params`. A negative orientation_variance marks the
/// orientation as unknown (orientation_covariance[0] = -1). `gyro_bias` (raw LSB, the sensor's
/// axes) is subtracted from the gyro before it is scaled and mapped.
sensor_msgs::Imu toImu(const protocol::body::Telemetry& telemetry, const ImuParams& params,
                       const ros::Time& stamp, const std::array<double, 3>& gyro_bias = {});

/// The yaw (rad, [-pi, pi]) of the orientation toImu() publishes: the board's attitude through
/// ~imu/axis_map, i.e. the heading of the imu frame (~base/use_imu_heading feeds it to odometry).
double imuYaw(const protocol::body::Telemetry& telemetry, const ImuParams& params);

/// The 8 raw foot readings, or nothing when the frame did not carry the foot block.
std::optional<serial_robot_driver::FootPressure> toFootPressure(
    const protocol::body::Telemetry& telemetry, const ros::Time& stamp,
    const std::string& frame_id = "");

/// The whole frame in raw units (for rosbag). `joints` give the servo ids in frame order.
serial_robot_driver::Telemetry toTelemetryMsg(const protocol::body::Telemetry& telemetry,
                                              const std::vector<device::BodyJoint>& joints,
                                              const ros::Time& stamp);

/// A joint command taken out of a JointState (only name and position matter).
struct JointCommand {
  std::vector<std::string> names;
  std::vector<double> positions;
};
JointCommand fromJointState(const sensor_msgs::JointState& msg);

/// How writeStatusReport treats the status's summary so far.
enum class SummaryWrite {
  kReplace,  ///< the report's level and message are the status's (the updater's fresh status)
  kMerge,    ///< merged into another check's verdict (DiagnosticStatusWrapper::mergeSummary)
};
/// A core status report as the updater publishes it: its summary, its hardware_id when it has
/// one, and its values appended in order.
void writeStatusReport(const device::StatusReport& report,
                       diagnostic_updater::DiagnosticStatusWrapper& status,
                       SummaryWrite summary = SummaryWrite::kReplace);

}  // namespace serial_robot_driver::ros_layer
