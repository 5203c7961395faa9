// Conversions from the decoded telemetry to ROS messages (and JointState back to a command). Pure
// functions: no roscore needed.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>

#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {
namespace {

using protocol::body::Telemetry;

constexpr double kRadPerTick = 2.0 * M_PI / 4096.0;
constexpr double kHalfSqrt2 = 0.70710678118654752;

// The values of docs/protocols.md, section 2b's golden frame (positions 2048, 1024, speeds 10, -5,
// IMU 1, -1, 16384, 0, 0, 100, 0, 0, -16384), optionally with a foot block.
Telemetry goldenTelemetry(bool with_foot = false) {
  Telemetry t;
  t.servo_count = 2;
  t.servos[0] = {2048, 10};
  t.servos[1] = {1024, -5};
  t.imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  t.has_foot = with_foot;
  if (with_foot) t.foot = {0x0201, 0x0403, 5, 6, 7, 8, 9, 0xFFFF};
  return t;
}

std::vector<device::BodyJoint> joints(int direction_of_second = 1, double velocity_scale = 0.0) {
  BodyParams params;
  params.servo_ids = {2, 3};
  params.joint_names = {"hip", "knee"};
  params.zero_ticks = {2048, 2048};
  params.directions = {1, direction_of_second};
  params.calibration.ticks_per_revolution = 4096;
  params.calibration.velocity_scale = velocity_scale;
  return makeBodyJoints(params);
}

void expectQuaternion(const geometry_msgs::Quaternion& q, double x, double y, double z, double w) {
  // q and -q are the same rotation: compare up to sign.
  const double sign = (q.w * w + q.x * x + q.y * y + q.z * z) < 0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * q.x, x, 1e-9);
  EXPECT_NEAR(sign * q.y, y, 1e-9);
  EXPECT_NEAR(sign * q.z, z, 1e-9);
  EXPECT_NEAR(sign * q.w, w, 1e-9);
}

// --- time ----------------------------------------------------------------------------------------

TEST(ConversionsTime, ArrivalIsNowMinusItsAge) {
  const auto steady_now = std::chrono::steady_clock::time_point(std::chrono::seconds(500));
  const auto arrival = steady_now - std::chrono::milliseconds(250);
  const ros::Time stamp = toRosTime(arrival, ros::Time(1000, 0), steady_now);
  EXPECT_EQ(stamp, ros::Time(999, 750000000));
}

TEST(ConversionsTime, FutureArrivalIsNowAndOldArrivalSaturatesAtZero) {
  const auto steady_now = std::chrono::steady_clock::time_point(std::chrono::seconds(500));
  EXPECT_EQ(toRosTime(steady_now + std::chrono::milliseconds(1), ros::Time(10, 0), steady_now),
            ros::Time(10, 0));
  EXPECT_EQ(toRosTime(steady_now - std::chrono::seconds(20), ros::Time(10, 0), steady_now),
            ros::Time(0));
}

// --- parameters ----------------------------------------------------------------------------------

TEST(ConversionsJoints, BodyParamsBecomeJointsInServoIdOrder) {
  BodyParams params;
  params.servo_ids = {7, 4};
  params.joint_names = {"a", "b"};
  params.zero_ticks = {100, 200};
  params.directions = {-1, 1};
  params.calibration.ticks_per_revolution = 1024;
  params.calibration.velocity_scale = 0.5;
  const std::vector<device::BodyJoint> j = makeBodyJoints(params);
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

// --- quaternion ----------------------------------------------------------------------------------

TEST(ConversionsQuaternion, Identity) {
  expectQuaternion(quaternionFromRollPitchYaw(0, 0, 0), 0, 0, 0, 1);
}

TEST(ConversionsQuaternion, YawOnly) {
  expectQuaternion(quaternionFromRollPitchYaw(0, 0, M_PI / 2), 0, 0, kHalfSqrt2, kHalfSqrt2);
  expectQuaternion(quaternionFromRollPitchYaw(0, 0, -M_PI / 2), 0, 0, -kHalfSqrt2, kHalfSqrt2);
}

TEST(ConversionsQuaternion, RollOnlyAndPitchOnly) {
  expectQuaternion(quaternionFromRollPitchYaw(M_PI / 2, 0, 0), kHalfSqrt2, 0, 0, kHalfSqrt2);
  expectQuaternion(quaternionFromRollPitchYaw(0, M_PI / 2, 0), 0, kHalfSqrt2, 0, kHalfSqrt2);
}

TEST(ConversionsQuaternion, CombinedAnglesAreYawThenPitchThenRoll) {
  const double roll = 0.1, pitch = -0.2, yaw = 0.3;
  const geometry_msgs::Quaternion q = quaternionFromRollPitchYaw(roll, pitch, yaw);
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

// --- JointState ----------------------------------------------------------------------------------

TEST(ConversionsJointState, PositionsInRadiansAndNoVelocityWithoutItsScale) {
  const ros::Time stamp(42, 5);
  const sensor_msgs::JointState msg = toJointState(goldenTelemetry(), joints(), stamp);
  EXPECT_EQ(msg.header.stamp, stamp);
  ASSERT_EQ(msg.name, (std::vector<std::string>{"hip", "knee"}));
  ASSERT_EQ(msg.position.size(), 2u);
  EXPECT_NEAR(msg.position[0], 0.0, 1e-12);
  EXPECT_NEAR(msg.position[1], -M_PI / 2, 1e-12);
  EXPECT_TRUE(msg.velocity.empty());  // velocity_scale 0: unknown, not guessed
  EXPECT_TRUE(msg.effort.empty());
}

TEST(ConversionsJointState, ReversedJointAndVelocityScale) {
  const sensor_msgs::JointState msg =
      toJointState(goldenTelemetry(), joints(-1, 0.02), ros::Time());
  EXPECT_NEAR(msg.position[1], M_PI / 2, 1e-12);
  EXPECT_NEAR(msg.velocity[0], 0.2, 1e-12);  // 10 * 0.02
  EXPECT_NEAR(msg.velocity[1], 0.1, 1e-12);  // -1 * 0.02 * -5
}

// --- Imu -----------------------------------------------------------------------------------------

TEST(ConversionsImu, ScaledValuesOrientationAndCovariances) {
  ImuParams params;
  params.frame_id = "imu_test";
  params.accel_scale = 0.5;
  params.gyro_scale = 0.25;
  params.angle_scale = M_PI / 32768.0;  // 180 deg full scale: -16384 is -90 deg
  params.orientation_variance = 0.1;
  params.angular_velocity_variance = 0.2;
  params.linear_acceleration_variance = 0.3;
  const ros::Time stamp(7, 0);
  const sensor_msgs::Imu msg = toImu(goldenTelemetry(), params, stamp);

  EXPECT_EQ(msg.header.stamp, stamp);
  EXPECT_EQ(msg.header.frame_id, "imu_test");
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.x, 0.5);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.y, -0.5);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.z, 8192.0);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.x, 0.0);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.y, 0.0);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.z, 25.0);
  expectQuaternion(msg.orientation, 0, 0, -kHalfSqrt2, kHalfSqrt2);  // yaw -90 deg

  const boost::array<double, 9> orientation = {0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1};
  const boost::array<double, 9> gyro = {0.2, 0, 0, 0, 0.2, 0, 0, 0, 0.2};
  const boost::array<double, 9> accel = {0.3, 0, 0, 0, 0.3, 0, 0, 0, 0.3};
  EXPECT_EQ(msg.orientation_covariance, orientation);
  EXPECT_EQ(msg.angular_velocity_covariance, gyro);
  EXPECT_EQ(msg.linear_acceleration_covariance, accel);
}

TEST(ConversionsImu, DefaultScalesAreTheDatasheetOnes) {
  const sensor_msgs::Imu msg = toImu(goldenTelemetry(), ImuParams(), ros::Time());
  // 16384 LSB = 8 g; 100 LSB = 100 * 2000/32768 deg/s; -16384 LSB = -90 deg.
  EXPECT_NEAR(msg.linear_acceleration.z, 8 * 9.80665, 0.01);
  EXPECT_NEAR(msg.angular_velocity.z, 100 * 2000.0 / 32768 * M_PI / 180, 1e-5);
  EXPECT_NEAR(msg.orientation.z, -kHalfSqrt2, 1e-5);
}

// Axis map [-y, x, z]: imu x = -sensor y, imu y = sensor x (the board turned +90 deg about z).
// Golden raw values: accel (1, -1, 16384), gyro (0, 0, 100), yaw -16384 (-90 deg).
TEST(ConversionsImu, AxisMapRemapsVectorsAndTurnsTheOrientation) {
  ImuParams params;
  params.accel_scale = 0.5;
  params.gyro_scale = 0.25;
  params.angle_scale = M_PI / 32768.0;
  params.axis_map = {"-y", "x", "z"};
  const sensor_msgs::Imu msg = toImu(goldenTelemetry(), params, ros::Time());
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.x, 0.5);   // -(-1 * 0.5)
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.y, 0.5);   // 1 * 0.5
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.z, 8192.0);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.z, 25.0);
  // The sensor's yaw -90 deg, seen from a frame turned +90 deg about z: yaw -180 deg.
  EXPECT_NEAR(std::abs(msg.orientation.z), 1.0, 1e-9);
  EXPECT_NEAR(msg.orientation.w, 0.0, 1e-9);
}

// The gyro bias is raw (LSB, sensor axes): subtracted before the scale and the axis map, so a new
// gyro_scale scales it too. Golden gyro (0, 0, 100) minus (4, -2, 10) = (-4, 2, 90) LSB.
TEST(ConversionsImu, GyroBiasIsSubtractedInRawUnitsBeforeTheScaleAndTheAxisMap) {
  ImuParams params;
  params.gyro_scale = 0.25;
  params.axis_map = {"-y", "x", "z"};
  const std::array<double, 3> bias{4, -2, 10};
  sensor_msgs::Imu msg = toImu(goldenTelemetry(), params, ros::Time(), bias);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.x, -0.5);  // -(2 * 0.25)
  EXPECT_DOUBLE_EQ(msg.angular_velocity.y, -1.0);  // -4 * 0.25
  EXPECT_DOUBLE_EQ(msg.angular_velocity.z, 22.5);  // 90 * 0.25
  params.gyro_scale = 0.5;
  msg = toImu(goldenTelemetry(), params, ros::Time(), bias);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.z, 45.0);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.z,
                   toImu(goldenTelemetry(), params, ros::Time()).linear_acceleration.z)
      << "the accelerometer is left alone";
}

TEST(ConversionsImu, UpsideDownMountFlipsYAndZ) {
  ImuParams params;
  params.accel_scale = 1.0;
  params.axis_map = {"x", "-y", "-z"};
  const sensor_msgs::Imu msg = toImu(goldenTelemetry(), params, ros::Time());
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.x, 1.0);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.y, 1.0);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.z, -16384.0);
}

TEST(ConversionsImu, AxisMapMatrixIsTheSignedPermutation) {
  Eigen::Matrix3d expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_TRUE(axisMapMatrix({"-y", "x", "z"}).isApprox(expected));
  EXPECT_TRUE(axisMapMatrix({"x", "y", "z"}).isIdentity());
}

TEST(ConversionsImu, NegativeOrientationVarianceMeansNoOrientation) {
  ImuParams params;
  params.orientation_variance = -1;
  const sensor_msgs::Imu msg = toImu(goldenTelemetry(), params, ros::Time());
  EXPECT_EQ(msg.orientation_covariance[0], -1.0);
  EXPECT_EQ(msg.orientation_covariance[4], 0.0);
}

// imuYaw (~base/use_imu_heading) is the yaw of the orientation imu/data carries, axis map included.
TEST(ConversionsImu, ImuYawIsTheHeadingOfThePublishedOrientation) {
  ImuParams params;
  params.angle_scale = M_PI / 32768.0;
  EXPECT_NEAR(imuYaw(goldenTelemetry(), params), -M_PI / 2, 1e-9);  // raw yaw -16384: -90 deg
  // Board turned +90 deg about z ([-y, x, z]): the imu frame's heading is -180 deg.
  params.axis_map = {"-y", "x", "z"};
  EXPECT_NEAR(std::abs(imuYaw(goldenTelemetry(), params)), M_PI, 1e-9);
  // Upside down ([x, -y, -z]) is a roll of 180 deg: the heading stays -90 deg.
  params.axis_map = {"x", "-y", "-z"};
  EXPECT_NEAR(imuYaw(goldenTelemetry(), params), -M_PI / 2, 1e-9);
  const sensor_msgs::Imu msg = toImu(goldenTelemetry(), params, ros::Time());
  const auto& q = msg.orientation;
  EXPECT_NEAR(imuYaw(goldenTelemetry(), params),
              std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)), 1e-9);
}

// --- FootPressure and Telemetry ------------------------------------------------------------------

TEST(ConversionsFootPressure, OnlyForFramesWithTheFootBlock) {
  EXPECT_FALSE(toFootPressure(goldenTelemetry(false), ros::Time(1, 0)).has_value());
  const auto msg = toFootPressure(goldenTelemetry(true), ros::Time(1, 0));
  ASSERT_TRUE(msg.has_value());
  EXPECT_EQ(msg->header.stamp, ros::Time(1, 0));
  const boost::array<uint16_t, 8> expected = {0x0201, 0x0403, 5, 6, 7, 8, 9, 0xFFFF};
  EXPECT_EQ(msg->pressure, expected);
}

TEST(ConversionsTelemetry, RawFrameWithServoIds) {
  const ros::Time stamp(3, 4);
  const serial_robot_driver::Telemetry msg = toTelemetryMsg(goldenTelemetry(), joints(), stamp);
  EXPECT_EQ(msg.header.stamp, stamp);
  EXPECT_EQ(msg.servo_ids, (std::vector<uint8_t>{2, 3}));
  EXPECT_EQ(msg.positions, (std::vector<uint16_t>{2048, 1024}));
  EXPECT_EQ(msg.speeds, (std::vector<int16_t>{10, -5}));
  const boost::array<int16_t, 9> imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  EXPECT_EQ(msg.imu, imu);
  EXPECT_FALSE(msg.has_foot);
  EXPECT_TRUE(msg.foot.empty());
}

TEST(ConversionsTelemetry, FootReadingsWhenPresent) {
  const serial_robot_driver::Telemetry msg =
      toTelemetryMsg(goldenTelemetry(true), joints(), ros::Time());
  EXPECT_TRUE(msg.has_foot);
  EXPECT_EQ(msg.foot, (std::vector<uint16_t>{0x0201, 0x0403, 5, 6, 7, 8, 9, 0xFFFF}));
}

// --- JointState -> command -----------------------------------------------------------------------

TEST(ConversionsJointCommand, NamesAndPositionsOnly) {
  sensor_msgs::JointState msg;
  msg.name = {"knee", "hip"};
  msg.position = {0.5, -0.25};
  msg.velocity = {1.0, 2.0};
  const JointCommand command = fromJointState(msg);
  EXPECT_EQ(command.names, msg.name);
  EXPECT_EQ(command.positions, msg.position);
}

TEST(WriteStatusReport, ReplacesTheUpdatersPlaceholderSummaryAndAppendsTheValues) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  // What diagnostic_updater::Updater hands a task.
  status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "No message was set");
  status.hardware_id = "node";
  device::StatusReport report;
  report.summary(device::StatusLevel::kWarn, "battery 19 % (below 20 %)");
  report.hardware_id = "/dev/ttyUSB0";
  report.add("connected", true);
  report.add("battery (%)", 19);
  writeStatusReport(report, status);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(status.message, "battery 19 % (below 20 %)");
  EXPECT_EQ(status.hardware_id, "/dev/ttyUSB0");
  ASSERT_EQ(status.values.size(), 2u);
  EXPECT_EQ(status.values[0].key, "connected");
  EXPECT_EQ(status.values[0].value, "True");
  EXPECT_EQ(status.values[1].key, "battery (%)");
  EXPECT_EQ(status.values[1].value, "19");

  device::StatusReport no_id;
  writeStatusReport(no_id, status);
  EXPECT_EQ(status.hardware_id, "/dev/ttyUSB0") << "a report without one keeps the status's";
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK);
}

TEST(WriteStatusReport, MergesIntoAnotherChecksVerdict) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "Frequency too low.");
  status.add("Events in window", 3);
  device::StatusReport fine;
  writeStatusReport(fine, status, SummaryWrite::kMerge);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(status.message, "Frequency too low.");
  device::StatusReport stopped;
  stopped.mergeSummary(device::StatusLevel::kError, "telemetry stopped");
  stopped.add("frames decoded", 10);
  writeStatusReport(stopped, status, SummaryWrite::kMerge);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, "Frequency too low.; telemetry stopped");
  ASSERT_EQ(status.values.size(), 2u);
  EXPECT_EQ(status.values[1].key, "frames decoded");
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
