// What a telemetry frame measures, ROS-free: the joints from ~body, joint radians, the attitude
// quaternion, the IMU in the robot's axes (~imu/axis_map, the gyro bias) and its heading. The ROS
// messages that carry these are tested in test/unit/test_conversions.cpp.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "serial_robot_driver/devices/body/body_readings.h"
#include "support/body_telemetry_fixture.h"

namespace serial_robot_driver::devices::body {
namespace {

using test_support::expectQuaternion;
using test_support::goldenBodyTelemetry;
using test_support::hipAndKnee;

constexpr double kHalfSqrt2 = 0.70710678118654752;

// --- parameters ----------------------------------------------------------------------------------

TEST(BodyReadingsJoints, BodyParamsBecomeJointsInServoIdOrder) {
  BodyParams params;
  params.servo_ids = {7, 4};
  params.joint_names = {"a", "b"};
  params.zero_ticks = {100, 200};
  params.directions = {-1, 1};
  params.calibration.ticks_per_revolution = 1024;
  params.calibration.velocity_scale = 0.5;
  const std::vector<BodyJoint> j = makeBodyJoints(params);
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0].name, "a");
  EXPECT_EQ(j[0].servo_id, 7);
  EXPECT_EQ(j[0].calibration.zero_ticks, 100);
  EXPECT_EQ(j[0].calibration.direction, -1);
  EXPECT_EQ(j[1].name, "b");
  EXPECT_EQ(j[1].servo_id, 4);
  EXPECT_EQ(j[1].calibration.zero_ticks, 200);
  EXPECT_EQ(j[1].calibration.direction, 1);
  EXPECT_EQ(j[1].calibration.ticks_per_revolution, 1024);
  EXPECT_EQ(j[1].calibration.velocity_scale, 0.5);
}

// --- joint radians -------------------------------------------------------------------------------

TEST(BodyReadingsJoints, PositionsInRadiansAndNoVelocityWithoutItsScale) {
  const JointReadings readings = jointReadings(goldenBodyTelemetry(), hipAndKnee());
  ASSERT_EQ(readings.names, (std::vector<std::string>{"hip", "knee"}));
  ASSERT_EQ(readings.positions.size(), 2u);
  EXPECT_NEAR(readings.positions[0], 0.0, 1e-12);
  EXPECT_NEAR(readings.positions[1], -M_PI / 2, 1e-12);
  EXPECT_TRUE(readings.velocities.empty());  // velocity_scale 0: unknown, not guessed
}

TEST(BodyReadingsJoints, ReversedJointAndVelocityScale) {
  const JointReadings readings = jointReadings(goldenBodyTelemetry(), hipAndKnee(-1, 0.02));
  EXPECT_NEAR(readings.positions[1], M_PI / 2, 1e-12);
  EXPECT_NEAR(readings.velocities[0], 0.2, 1e-12);  // 10 * 0.02
  EXPECT_NEAR(readings.velocities[1], 0.1, 1e-12);  // -1 * 0.02 * -5
}

TEST(BodyReadingsJoints, JointsBeyondTheFramesServoCountAreLeftOut) {
  Telemetry telemetry = goldenBodyTelemetry();
  telemetry.servo_count = 1;
  EXPECT_EQ(jointReadings(telemetry, hipAndKnee()).names, (std::vector<std::string>{"hip"}));
}

TEST(BodyReadingsJoints, UpdatedInPlaceFrameAfterFrameWithoutNewStorage) {
  JointReadings readings;
  updateJointReadings(goldenBodyTelemetry(), hipAndKnee(-1, 0.02), &readings);
  const std::string* names = readings.names.data();
  const uint64_t generation = readings.names_generation;
  const double* positions = readings.positions.data();
  Telemetry next = goldenBodyTelemetry();
  next.servos[1].position = static_cast<uint16_t>(next.servos[1].position + 512);  // knee moved
  updateJointReadings(next, hipAndKnee(-1, 0.02), &readings);
  EXPECT_EQ(readings.names.data(), names) << "the names are kept";
  EXPECT_EQ(readings.names_generation, generation) << "and a message holding them keeps them";
  EXPECT_EQ(readings.positions.data(), positions) << "the storage is reused";
  EXPECT_EQ(readings.names, (std::vector<std::string>{"hip", "knee"}));
  const JointReadings fresh = jointReadings(next, hipAndKnee(-1, 0.02));
  EXPECT_EQ(readings.positions, fresh.positions);
  EXPECT_EQ(readings.velocities, fresh.velocities);
  EXPECT_NE(readings.positions[1],
            jointReadings(goldenBodyTelemetry(), hipAndKnee(-1, 0.02)).positions[1]);

  next.servo_count = 1;  // fewer joints in the frame: the names follow
  updateJointReadings(next, hipAndKnee(-1, 0.02), &readings);
  EXPECT_EQ(readings.names, (std::vector<std::string>{"hip"}));
  EXPECT_NE(readings.names_generation, generation) << "a message holding the old names copies anew";
  EXPECT_EQ(readings.positions.size(), 1u);
  EXPECT_EQ(readings.velocities.size(), 1u);
}

// --- quaternion ----------------------------------------------------------------------------------

TEST(BodyReadingsQuaternion, Identity) {
  expectQuaternion(quaternionFromRollPitchYaw(0, 0, 0), 0, 0, 0, 1);
}

TEST(BodyReadingsQuaternion, YawOnly) {
  expectQuaternion(quaternionFromRollPitchYaw(0, 0, M_PI / 2), 0, 0, kHalfSqrt2, kHalfSqrt2);
  expectQuaternion(quaternionFromRollPitchYaw(0, 0, -M_PI / 2), 0, 0, -kHalfSqrt2, kHalfSqrt2);
}

TEST(BodyReadingsQuaternion, RollOnlyAndPitchOnly) {
  expectQuaternion(quaternionFromRollPitchYaw(M_PI / 2, 0, 0), kHalfSqrt2, 0, 0, kHalfSqrt2);
  expectQuaternion(quaternionFromRollPitchYaw(0, M_PI / 2, 0), 0, kHalfSqrt2, 0, kHalfSqrt2);
}

TEST(BodyReadingsQuaternion, CombinedAnglesAreYawThenPitchThenRoll) {
  const double roll = 0.1, pitch = -0.2, yaw = 0.3;
  const Quaternion q = quaternionFromRollPitchYaw(roll, pitch, yaw);
  // Against Eigen's axis-angle composition Rz(yaw) Ry(pitch) Rx(roll) ...
  const Eigen::Quaterniond expected = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  expectQuaternion(q, expected.x(), expected.y(), expected.z(), expected.w());
  // ... and against the closed-form ZYX formula, which does not involve Eigen at all.
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  expectQuaternion(q, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                   cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy);
  // The rotation is not the other order (roll applied last), which would differ here.
  const Eigen::Quaterniond wrong_order = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
                                         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                         Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  EXPECT_GT(std::abs(q.x - wrong_order.x()) + std::abs(q.z - wrong_order.z()), 1e-3);
}

// --- IMU in the robot's axes ---------------------------------------------------------------------

TEST(BodyReadingsImu, ScaledValuesAndOrientation) {
  ImuParams params;
  params.accel_scale = 0.5;
  params.gyro_scale = 0.25;
  params.angle_scale = M_PI / 32768.0;  // 180 deg full scale: -16384 is -90 deg
  const ImuReading reading = imuReading(goldenBodyTelemetry(), params);
  EXPECT_DOUBLE_EQ(reading.linear_acceleration.x(), 0.5);
  EXPECT_DOUBLE_EQ(reading.linear_acceleration.y(), -0.5);
  EXPECT_DOUBLE_EQ(reading.linear_acceleration.z(), 8192.0);
  EXPECT_DOUBLE_EQ(reading.angular_velocity.x(), 0.0);
  EXPECT_DOUBLE_EQ(reading.angular_velocity.y(), 0.0);
  EXPECT_DOUBLE_EQ(reading.angular_velocity.z(), 25.0);
  expectQuaternion(reading.orientation, 0, 0, -kHalfSqrt2, kHalfSqrt2);  // yaw -90 deg
}

// Axis map [-y, x, z]: imu x = -sensor y, imu y = sensor x (the board turned +90 deg about z).
TEST(BodyReadingsImu, AxisMapRemapsVectorsAndTurnsTheOrientation) {
  ImuParams params;
  params.accel_scale = 0.5;
  params.gyro_scale = 0.25;
  params.angle_scale = M_PI / 32768.0;
  params.axis_map = {"-y", "x", "z"};
  const ImuReading reading = imuReading(goldenBodyTelemetry(), params);
  EXPECT_DOUBLE_EQ(reading.linear_acceleration.x(), 0.5);  // -(-1 * 0.5)
  EXPECT_DOUBLE_EQ(reading.linear_acceleration.y(), 0.5);  // 1 * 0.5
  EXPECT_DOUBLE_EQ(reading.angular_velocity.z(), 25.0);
  // The sensor's yaw -90 deg, seen from a frame turned +90 deg about z: yaw -180 deg.
  EXPECT_NEAR(std::abs(reading.orientation.z), 1.0, 1e-9);
  EXPECT_NEAR(reading.orientation.w, 0.0, 1e-9);
}

// Golden gyro (0, 0, 100) minus (4, -2, 10) = (-4, 2, 90) LSB, then scaled and mapped.
TEST(BodyReadingsImu, GyroBiasIsSubtractedInRawUnitsBeforeTheScaleAndTheAxisMap) {
  ImuParams params;
  params.gyro_scale = 0.25;
  params.axis_map = {"-y", "x", "z"};
  const ImuReading reading = imuReading(goldenBodyTelemetry(), params, {4, -2, 10});
  EXPECT_DOUBLE_EQ(reading.angular_velocity.x(), -0.5);  // -(2 * 0.25)
  EXPECT_DOUBLE_EQ(reading.angular_velocity.y(), -1.0);  // -4 * 0.25
  EXPECT_DOUBLE_EQ(reading.angular_velocity.z(), 22.5);  // 90 * 0.25
}

TEST(BodyReadingsImu, AxisMapMatrixIsTheSignedPermutation) {
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(axisMapMatrix({"-y", "x", "z"}).isApprox(expected));
  EXPECT_TRUE(axisMapMatrix({"x", "y", "z"}).isIdentity());
}

// imuYaw (~base/use_imu_heading) is the yaw of the orientation imu/data carries, axis map included.
TEST(BodyReadingsImu, ImuYawIsTheHeadingOfThePublishedOrientation) {
  ImuParams params;
  params.angle_scale = M_PI / 32768.0;
  EXPECT_NEAR(imuYaw(goldenBodyTelemetry(), params), -M_PI / 2, 1e-9);  // raw yaw -16384: -90 deg
  // Board turned +90 deg about z ([-y, x, z]): the imu frame's heading is -180 deg.
  params.axis_map = {"-y", "x", "z"};
  EXPECT_NEAR(std::abs(imuYaw(goldenBodyTelemetry(), params)), M_PI, 1e-9);
  // Upside down ([x, -y, -z]) is a roll of 180 deg: the heading stays -90 deg.
  params.axis_map = {"x", "-y", "-z"};
  EXPECT_NEAR(imuYaw(goldenBodyTelemetry(), params), -M_PI / 2, 1e-9);
  const Quaternion& q = imuReading(goldenBodyTelemetry(), params).orientation;
  EXPECT_NEAR(imuYaw(goldenBodyTelemetry(), params),
              std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)), 1e-9);
}

}  // namespace
}  // namespace serial_robot_driver::devices::body
