// What a telemetry frame measures, in SI units and the robot's axes: joint angles and rates, and
// the IMU's accel, gyro and orientation through ~imu/axis_map (and the heading odometry follows).
// ROS-free: a front end copies these fields into its messages.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/body/body_params.h"

namespace serial_robot_driver::devices::body {

/// The joints configured from ~body (servo_ids, joint_names, zero_ticks, directions,
/// ticks_per_revolution, velocity_scale), in frame order. Assumes validated parameters.
std::vector<BodyJoint> makeBodyJoints(const BodyParams& params);

/// Joint positions (rad) and velocities (rad/s) of every configured joint, in frame order.
struct JointReadings {
  std::vector<std::string> names;
  /// Changes whenever `names` does, so that a message that kept the names need not copy them again.
  uint64_t names_generation = 0;
  std::vector<double> positions;
  /// Empty when the speed's scale is unknown (~body/velocity_scale 0): not guessed.
  std::vector<double> velocities;
};
/// Joints beyond the frame's servo_count are left out (cannot happen when the frame was decoded
/// for these joints).
JointReadings jointReadings(const Telemetry& telemetry, const std::vector<BodyJoint>& joints);
/// jointReadings() into `readings`, which keeps its vectors' capacity (and its names while the
/// joints are the same), so the reader thread converts each frame once without allocating.
void updateJointReadings(const Telemetry& telemetry, const std::vector<BodyJoint>& joints,
                         JointReadings* readings);

/// What converting a frame needs of the joints, each kind laid out together: the reader thread
/// reads every joint's calibration each frame, and these take 24 bytes a joint against a
/// BodyJoint's 64 (the name's string in between), so fewer cache lines a frame.
struct JointConversion {
  std::vector<std::string> names;
  std::vector<JointCalibration> calibrations;
};
JointConversion makeJointConversion(const std::vector<BodyJoint>& joints);
/// updateJointReadings() with the joints' conversion made beforehand, as the reader thread does.
void updateJointReadings(const Telemetry& telemetry, const JointConversion& joints,
                         JointReadings* readings);

/// A rotation as a unit quaternion.
struct Quaternion {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
};

/// Orientation quaternion from attitude angles in rad, applied as yaw (Z) * pitch (Y) * roll (X).
Quaternion quaternionFromRollPitchYaw(double roll, double pitch, double yaw);

/// The signed permutation matrix of ~imu/axis_map (v_imu = M v_sensor); identity for a map that
/// does not parse (validate() refuses those at start-up).
Eigen::Matrix3d axisMapMatrix(const std::vector<std::string>& axis_map);

/// One frame's IMU values in the imu frame (the sensor's axes through ~imu/axis_map).
struct ImuReading {
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  ///< m/s^2
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     ///< rad/s
  Quaternion orientation;                                         ///< R_world_imu
};
/// Accel and gyro scaled from raw LSB, orientation from the attitude angles. `gyro_bias` (raw
/// LSB, the sensor's axes) is subtracted from the gyro before it is scaled and mapped.
ImuReading imuReading(const Telemetry& telemetry, const ImuParams& params,
                      const std::array<double, 3>& gyro_bias = {});
/// The same with the axis map's matrix (axisMapMatrix(params.axis_map)) worked out beforehand, as
/// the reader thread does once per set of ~imu values rather than once per frame.
ImuReading imuReading(const Telemetry& telemetry, const ImuParams& params,
                      const Eigen::Matrix3d& axes, const std::array<double, 3>& gyro_bias);

/// The IMU's covariances as sensor_msgs/Imu carries them (row-major 3x3, diagonal from `params`'s
/// variances; REP-145: a negative orientation_variance marks the orientation as unknown, element
/// 0 = -1 and the rest 0), for every front end to copy.
struct ImuCovariances {
  std::array<double, 9> orientation{};
  std::array<double, 9> angular_velocity{};
  std::array<double, 9> linear_acceleration{};
};
ImuCovariances imuCovariances(const ImuParams& params);

/// The yaw (rad, [-pi, pi]) of imuReading()'s orientation: the board's attitude through
/// ~imu/axis_map, i.e. the heading of the imu frame (~base/use_imu_heading feeds it to odometry).
double imuYaw(const Telemetry& telemetry, const ImuParams& params);
/// The same with axisMapMatrix(params.axis_map) worked out beforehand.
double imuYaw(const Telemetry& telemetry, const ImuParams& params, const Eigen::Matrix3d& axes);

}  // namespace serial_robot_driver::devices::body
