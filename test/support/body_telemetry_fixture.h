// The body's decoded golden telemetry and a two-joint body, shared by the codec, readings and ROS
// conversion tests (values written by hand from docs/protocols.md, section 2b).
#pragma once

#include <gtest/gtest.h>

#include <vector>

#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/body/body_readings.h"

namespace test_support {

namespace devices = serial_robot_driver::devices;

/// Section 2b's golden frame decoded: positions 2048, 1024, speeds 10, -5, IMU 1, -1, 16384, 0,
/// 0, 100, 0, 0, -16384; with `with_foot`, a foot block of its own (0x0201, 0x0403, 5..9, 0xFFFF).
inline devices::body::Telemetry goldenBodyTelemetry(bool with_foot = false) {
  devices::body::Telemetry t;
  t.servo_count = 2;
  t.servos[0] = {2048, 10};
  t.servos[1] = {1024, -5};
  t.imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  t.has_foot = with_foot;
  if (with_foot) t.foot = {0x0201, 0x0403, 5, 6, 7, 8, 9, 0xFFFF};
  return t;
}

/// Servos 2 and 3 as "hip" and "knee", zero at 2048 ticks, 4096 ticks a turn.
inline std::vector<devices::body::BodyJoint> hipAndKnee(int direction_of_second = 1,
                                                        double velocity_scale = 0.0) {
  devices::body::BodyParams params;
  params.servo_ids = {2, 3};
  params.joint_names = {"hip", "knee"};
  params.zero_ticks = {2048, 2048};
  params.directions = {1, direction_of_second};
  params.calibration.ticks_per_revolution = 4096;
  params.calibration.velocity_scale = velocity_scale;
  return devices::body::makeBodyJoints(params);
}

/// `q` is the rotation (x, y, z, w); q and -q are the same rotation, so compared up to sign.
template <typename Quaternion>
void expectQuaternion(const Quaternion& q, double x, double y, double z, double w) {
  const double sign = (q.w * w + q.x * x + q.y * y + q.z * z) < 0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * q.x, x, 1e-9);
  EXPECT_NEAR(sign * q.y, y, 1e-9);
  EXPECT_NEAR(sign * q.z, z, 1e-9);
  EXPECT_NEAR(sign * q.w, w, 1e-9);
}

}  // namespace test_support
