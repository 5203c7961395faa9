#include "serial_robot_driver/devices/base/base_readings.h"

#include <cmath>

namespace serial_robot_driver::devices::base {

BatteryReading batteryReading(uint8_t percent) { return {percent / 100.0}; }

YawRotation yawRotation(double yaw) { return {std::sin(yaw / 2.0), std::cos(yaw / 2.0)}; }

OdometryCovariances odometryCovariances(double position_variance, double yaw_variance) {
  OdometryCovariances covariances;
  auto& pose = covariances.pose;
  pose[0] = pose[7] = position_variance;
  pose[14] = pose[21] = pose[28] = kNotEstimatedVariance;
  pose[35] = yaw_variance;
  auto& twist = covariances.twist;
  twist[0] = kTwistLinearVariance;
  twist[7] = kTwistLateralVariance;
  twist[14] = twist[21] = twist[28] = kNotEstimatedVariance;
  twist[35] = kTwistAngularVariance;
  return covariances;
}

}  // namespace serial_robot_driver::devices::base
