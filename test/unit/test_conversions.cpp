// Conversions from the decoded telemetry to ROS messages (and JointState back to a command). Pure
// functions: no roscore needed. The values behind them (joint radians, the IMU in the robot's axes,
// its heading) are tested in the core: src/devices/body/test/test_body_readings.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "serial_robot_driver/devices/base/ros/base_conversions.h"
#include "serial_robot_driver/devices/body/ros/body_conversions.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/reused_message.h"
#include "support/body_telemetry_fixture.h"

namespace serial_robot_driver::ros_layer {
namespace {

using devices::body::BodyParams;
using devices::body::ImuParams;
using devices::body::Telemetry;

using test_support::expectQuaternion;
using test_support::goldenBodyTelemetry;
using test_support::hipAndKnee;

constexpr double kRadPerTick = 2.0 * M_PI / 4096.0;
constexpr double kHalfSqrt2 = 0.70710678118654752;

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

// --- JointState ----------------------------------------------------------------------------------

TEST(ConversionsJointState, PositionsInRadiansAndNoVelocityWithoutItsScale) {
  const ros::Time stamp(42, 5);
  const sensor_msgs::JointState msg =
      devices::body::ros::toJointState(goldenBodyTelemetry(), hipAndKnee(), stamp);
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
      devices::body::ros::toJointState(goldenBodyTelemetry(), hipAndKnee(-1, 0.02), ros::Time());
  EXPECT_NEAR(msg.position[1], M_PI / 2, 1e-12);
  EXPECT_NEAR(msg.velocity[0], 0.2, 1e-12);  // 10 * 0.02
  EXPECT_NEAR(msg.velocity[1], 0.1, 1e-12);  // -1 * 0.02 * -5
}

// A message filled again (the reader thread's, reused) is the one toJointState() builds afresh:
// nothing of the earlier contents survives.
TEST(ConversionsJointState, FillingAgainLeavesNothingOfTheLastMessage) {
  sensor_msgs::JointState msg;
  msg.header.frame_id = "stale";
  msg.name = {"a", "b", "c"};
  msg.position = {1, 2, 3};
  msg.velocity = {4, 5, 6};
  msg.effort = {7};
  const devices::body::JointReadings readings =
      devices::body::jointReadings(goldenBodyTelemetry(), hipAndKnee());
  devices::body::ros::fillJointState(readings, ros::Time(3, 4), &msg);
  EXPECT_EQ(msg, devices::body::ros::toJointState(readings, ros::Time(3, 4)));
  EXPECT_TRUE(msg.header.frame_id.empty());
  EXPECT_TRUE(msg.effort.empty());
}

// The reader thread's reused message keeps its names: the values are filled again without them,
// and everything else is what fillJointState() gives.
TEST(ConversionsJointState, FillingTheValuesLeavesTheNamesAlone) {
  const devices::body::JointReadings readings =
      devices::body::jointReadings(goldenBodyTelemetry(), hipAndKnee());
  sensor_msgs::JointState msg;
  msg.header.frame_id = "stale";
  msg.name = {"kept"};
  msg.position = {1, 2, 3};
  msg.effort = {7};
  devices::body::ros::fillJointStateValues(readings, ros::Time(3, 4), &msg);
  EXPECT_EQ(msg.name, std::vector<std::string>{"kept"});
  msg.name = readings.names;
  EXPECT_EQ(msg, devices::body::ros::toJointState(readings, ros::Time(3, 4)));
}

// The message published as a shared pointer is reused only while nobody else holds it (an
// in-process subscriber may keep the one it got).
TEST(ReusedMessage, ReusedOnlyWhenNobodyElseHoldsIt) {
  ReusedMessage<sensor_msgs::JointState> reused;
  sensor_msgs::JointState* first = &reused.next();
  EXPECT_TRUE(reused.renewed());
  EXPECT_EQ(&reused.next(), first);  // only ours: filled again
  EXPECT_FALSE(reused.renewed());
  sensor_msgs::JointState::ConstPtr kept = reused.get();
  first->name = {"kept"};
  sensor_msgs::JointState& second = reused.next();
  EXPECT_NE(&second, first);  // the subscriber's stays as it was
  EXPECT_TRUE(reused.renewed()) << "a new message: every field is to be filled";
  second.name = {"new"};
  EXPECT_EQ(kept->name, std::vector<std::string>{"kept"});
  EXPECT_EQ(reused.get()->name, std::vector<std::string>{"new"});
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
  const sensor_msgs::Imu msg = devices::body::ros::toImu(goldenBodyTelemetry(), params, stamp);

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
  const sensor_msgs::Imu msg =
      devices::body::ros::toImu(goldenBodyTelemetry(), ImuParams(), ros::Time());
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
  const sensor_msgs::Imu msg =
      devices::body::ros::toImu(goldenBodyTelemetry(), params, ros::Time());
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.x, 0.5);  // -(-1 * 0.5)
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.y, 0.5);  // 1 * 0.5
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
  sensor_msgs::Imu msg =
      devices::body::ros::toImu(goldenBodyTelemetry(), params, ros::Time(), bias);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.x, -0.5);  // -(2 * 0.25)
  EXPECT_DOUBLE_EQ(msg.angular_velocity.y, -1.0);  // -4 * 0.25
  EXPECT_DOUBLE_EQ(msg.angular_velocity.z, 22.5);  // 90 * 0.25
  params.gyro_scale = 0.5;
  msg = devices::body::ros::toImu(goldenBodyTelemetry(), params, ros::Time(), bias);
  EXPECT_DOUBLE_EQ(msg.angular_velocity.z, 45.0);
  EXPECT_DOUBLE_EQ(
      msg.linear_acceleration.z,
      devices::body::ros::toImu(goldenBodyTelemetry(), params, ros::Time()).linear_acceleration.z)
      << "the accelerometer is left alone";
}

TEST(ConversionsImu, UpsideDownMountFlipsYAndZ) {
  ImuParams params;
  params.accel_scale = 1.0;
  params.axis_map = {"x", "-y", "-z"};
  const sensor_msgs::Imu msg =
      devices::body::ros::toImu(goldenBodyTelemetry(), params, ros::Time());
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.x, 1.0);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.y, 1.0);
  EXPECT_DOUBLE_EQ(msg.linear_acceleration.z, -16384.0);
}

TEST(ConversionsImu, NegativeOrientationVarianceMeansNoOrientation) {
  ImuParams params;
  params.orientation_variance = -1;
  const sensor_msgs::Imu msg =
      devices::body::ros::toImu(goldenBodyTelemetry(), params, ros::Time());
  EXPECT_EQ(msg.orientation_covariance[0], -1.0);
  EXPECT_EQ(msg.orientation_covariance[4], 0.0);
}

// --- FootPressure and Telemetry ------------------------------------------------------------------

TEST(ConversionsFootPressure, OnlyForFramesWithTheFootBlock) {
  EXPECT_FALSE(
      devices::body::ros::toFootPressure(goldenBodyTelemetry(false), ros::Time(1, 0)).has_value());
  const auto msg = devices::body::ros::toFootPressure(goldenBodyTelemetry(true), ros::Time(1, 0));
  ASSERT_TRUE(msg.has_value());
  EXPECT_EQ(msg->header.stamp, ros::Time(1, 0));
  const boost::array<uint16_t, 8> expected = {0x0201, 0x0403, 5, 6, 7, 8, 9, 0xFFFF};
  EXPECT_EQ(msg->pressure, expected);
}

TEST(ConversionsTelemetry, RawFrameWithServoIds) {
  const ros::Time stamp(3, 4);
  const serial_robot_driver::Telemetry msg =
      devices::body::ros::toTelemetryMsg(goldenBodyTelemetry(), hipAndKnee(), stamp);
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
      devices::body::ros::toTelemetryMsg(goldenBodyTelemetry(true), hipAndKnee(), ros::Time());
  EXPECT_TRUE(msg.has_foot);
  EXPECT_EQ(msg.foot, (std::vector<uint16_t>{0x0201, 0x0403, 5, 6, 7, 8, 9, 0xFFFF}));
}

// --- JointState -> command -----------------------------------------------------------------------

TEST(ConversionsJointCommand, NamesAndPositionsOnly) {
  sensor_msgs::JointState msg;
  msg.name = {"knee", "hip"};
  msg.position = {0.5, -0.25};
  msg.velocity = {1.0, 2.0};
  const devices::body::JointCommand command = devices::body::ros::fromJointState(msg);
  EXPECT_EQ(command.names, msg.name);
  EXPECT_EQ(command.positions, msg.position);
}

// --- the base's readings -------------------------------------------------------------------------

TEST(ConversionsBattery, OnlyThePercentageIsKnown) {
  const sensor_msgs::BatteryState msg =
      devices::base::ros::toBatteryState(devices::base::batteryReading(57), ros::Time(2, 0));
  EXPECT_EQ(msg.header.stamp, ros::Time(2, 0));
  EXPECT_FLOAT_EQ(msg.percentage, 0.57f);
  EXPECT_TRUE(std::isnan(msg.voltage));
  EXPECT_TRUE(std::isnan(msg.design_capacity));
  EXPECT_EQ(msg.power_supply_status, sensor_msgs::BatteryState::POWER_SUPPLY_STATUS_UNKNOWN);
  EXPECT_TRUE(msg.present);
}

TEST(ConversionsOdometry, PoseTwistFramesAndCovariances) {
  devices::base::OdometrySample sample;
  sample.pose = {1.0, -2.0, M_PI / 2};
  sample.linear = 0.3;
  sample.angular = -0.4;
  sample.position_variance = 0.5;
  sample.yaw_variance = 0.6;
  const nav_msgs::Odometry odom =
      devices::base::ros::toOdometry(sample, {"odom", "base_link"}, ros::Time(5, 0));
  EXPECT_EQ(odom.header.stamp, ros::Time(5, 0));
  EXPECT_EQ(odom.header.frame_id, "odom");
  EXPECT_EQ(odom.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(odom.pose.pose.position.x, 1.0);
  EXPECT_DOUBLE_EQ(odom.pose.pose.position.y, -2.0);
  EXPECT_NEAR(odom.pose.pose.orientation.z, kHalfSqrt2, 1e-12);
  EXPECT_NEAR(odom.pose.pose.orientation.w, kHalfSqrt2, 1e-12);
  EXPECT_DOUBLE_EQ(odom.twist.twist.linear.x, 0.3);
  EXPECT_DOUBLE_EQ(odom.twist.twist.angular.z, -0.4);
  EXPECT_EQ(odom.pose.covariance[0], 0.5);
  EXPECT_EQ(odom.pose.covariance[7], 0.5);
  EXPECT_EQ(odom.pose.covariance[14], 1e6);
  EXPECT_EQ(odom.pose.covariance[35], 0.6);
  EXPECT_EQ(odom.twist.covariance[0], 0.0025);
  EXPECT_EQ(odom.twist.covariance[7], 1e-6);
  EXPECT_EQ(odom.twist.covariance[35], 0.01);
}

TEST(ConversionsOdometry, OdometryFilledAgainIsTheOneBuiltAfresh) {
  devices::base::OdometrySample sample;
  sample.pose = {1.0, -2.0, 0.3};
  sample.linear = 0.3;
  sample.angular = -0.4;
  sample.position_variance = 0.5;
  sample.yaw_variance = 0.6;
  // The last tick's message, with fields this one must overwrite (a longer frame name included).
  nav_msgs::Odometry msg;
  msg.header.frame_id = "a_much_longer_odom_frame_of_the_last_tick";
  msg.child_frame_id = "b";
  msg.pose.pose.position.z = 9;
  msg.pose.pose.orientation.x = 0.5;
  msg.twist.twist.linear.y = 2;
  msg.twist.twist.angular.x = 3;
  msg.pose.covariance[1] = 4;
  const devices::base::ros::OdomFrames frames{"odom", "base_link"};
  devices::base::ros::fillOdometry(sample, frames, ros::Time(5, 0), &msg);
  EXPECT_EQ(msg, devices::base::ros::toOdometry(sample, frames, ros::Time(5, 0)));
  EXPECT_EQ(msg.header.frame_id, "odom");
  EXPECT_EQ(msg.pose.pose.position.z, 0.0);
  EXPECT_EQ(msg.pose.covariance[1], 0.0);
}

TEST(ConversionsOdometry, WheelStatesFilledAgainAreTheOnesBuiltAfresh) {
  devices::base::OdometrySample sample;
  sample.wheel_angles = {1.5, -0.5};
  sample.wheel_rates = {0.25, -0.125};
  sensor_msgs::JointState msg;
  msg.name = {"a_long_joint_name_of_the_last_tick", "b", "c"};
  msg.position = {1, 2, 3};
  msg.effort = {7};
  devices::base::ros::fillWheelStates(sample, "base_link", "l", "r", ros::Time(1, 0), &msg);
  EXPECT_EQ(msg, devices::base::ros::toWheelStates(sample, "base_link", "l", "r", ros::Time(1, 0)));
}

TEST(ConversionsOdometry, WheelStatesAreTheSamplesAnglesAndRates) {
  devices::base::OdometrySample sample;
  sample.wheel_angles = {1.5, -0.5};
  sample.wheel_rates = {0.25, -0.125};
  const sensor_msgs::JointState msg =
      devices::base::ros::toWheelStates(sample, "base_link", "l", "r", ros::Time(1, 0));
  EXPECT_EQ(msg.header.frame_id, "base_link");
  EXPECT_EQ(msg.name, (std::vector<std::string>{"l", "r"}));
  EXPECT_EQ(msg.position, (std::vector<double>{1.5, -0.5}));
  EXPECT_EQ(msg.velocity, (std::vector<double>{0.25, -0.125}));
}

TEST(WriteStatusReport, ReplacesTheUpdatersPlaceholderSummaryAndAppendsTheValues) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  // What diagnostic_updater::Updater hands a task.
  status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "No message was set");
  status.hardware_id = "node";
  core::StatusReport report;
  report.summary(core::StatusLevel::kWarn, "battery 19 % (below 20 %)");
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

  core::StatusReport no_id;
  writeStatusReport(no_id, status);
  EXPECT_EQ(status.hardware_id, "/dev/ttyUSB0") << "a report without one keeps the status's";
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK);
}

TEST(WriteStatusReport, MergesIntoAnotherChecksVerdict) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "Frequency too low.");
  status.add("Events in window", 3);
  core::StatusReport fine;
  writeStatusReport(fine, status, SummaryWrite::kMerge);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(status.message, "Frequency too low.");
  core::StatusReport stopped;
  stopped.mergeSummary(core::StatusLevel::kError, "telemetry stopped");
  stopped.add("frames decoded", 10);
  writeStatusReport(stopped, status, SummaryWrite::kMerge);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, "Frequency too low.; telemetry stopped");
  ASSERT_EQ(status.values.size(), 2u);
  EXPECT_EQ(status.values[1].key, "frames decoded");
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
