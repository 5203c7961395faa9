// What the base's reports and odometry mean, in SI units (ROS-free): the battery's charge, the
// heading as a rotation, and how far the odometry's twist is to be trusted. A front end copies
// these fields into its messages.
#pragma once

#include <array>
#include <cstdint>

namespace serial_robot_driver::devices::base {

/// The battery as the base reports it: only its charge; voltage, current and the rest are unknown.
struct BatteryReading {
  double fraction = 0.0;  ///< 0 .. 1
};
BatteryReading batteryReading(uint8_t percent);

/// A heading (a rotation about z by `yaw` rad) as a unit quaternion; x and y are 0.
struct YawRotation {
  double z = 0.0;
  double w = 1.0;
};
YawRotation yawRotation(double yaw);

/// The odometry twist's variances: the twist is what the base was told, good to about one tick
/// per period (0.0245 m/s with the default geometry), plus what the wheels fail to follow.
constexpr double kTwistLinearVariance = 0.0025;  ///< (m/s)^2: std 0.05 m/s
constexpr double kTwistLateralVariance = 1e-6;   ///< a differential drive cannot slide sideways
constexpr double kTwistAngularVariance = 0.01;   ///< (rad/s)^2: std 0.1 rad/s
/// The variance of what the odometry does not estimate at all (z, roll, pitch).
constexpr double kNotEstimatedVariance = 1e6;

/// The odometry's covariances as nav_msgs/Odometry carries them (row-major 6x6: x, y, z, roll,
/// pitch, yaw), from a sample's variances, for every front end to copy.
struct OdometryCovariances {
  std::array<double, 36> pose{};
  std::array<double, 36> twist{};
};
/// Open loop: x, y and yaw grow with the distance travelled (kinematics::PoseCovarianceModel); z,
/// roll and pitch are not estimated at all. While the IMU's yaw is fused, `yaw_variance` is the
/// IMU's ~imu/orientation_variance.
OdometryCovariances odometryCovariances(double position_variance, double yaw_variance);

}  // namespace serial_robot_driver::devices::base
