// The base's readings, ROS-free: the battery's charge as a fraction and the heading as a rotation
// about z.
#include <gtest/gtest.h>

#include <cmath>

#include "serial_robot_driver/devices/base/base_readings.h"

namespace serial_robot_driver::devices::base {
namespace {

TEST(BaseReadings, BatteryPercentIsAFractionOfOne) {
  EXPECT_DOUBLE_EQ(batteryReading(0).fraction, 0.0);
  EXPECT_DOUBLE_EQ(batteryReading(57).fraction, 0.57);
  EXPECT_DOUBLE_EQ(batteryReading(100).fraction, 1.0);
}

TEST(BaseReadings, YawIsARotationAboutZ) {
  const YawRotation none = yawRotation(0.0);
  EXPECT_DOUBLE_EQ(none.z, 0.0);
  EXPECT_DOUBLE_EQ(none.w, 1.0);
  const YawRotation quarter = yawRotation(M_PI / 2);  // sin and cos of 45 deg
  EXPECT_NEAR(quarter.z, 0.70710678118654752, 1e-12);
  EXPECT_NEAR(quarter.w, 0.70710678118654752, 1e-12);
  const YawRotation back = yawRotation(-M_PI / 2);
  EXPECT_NEAR(back.z, -0.70710678118654752, 1e-12);
  EXPECT_NEAR(back.w, 0.70710678118654752, 1e-12);
}

}  // namespace
}  // namespace serial_robot_driver::devices::base
