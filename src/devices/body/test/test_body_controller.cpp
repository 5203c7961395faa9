// BodyController and JointCalibration: telemetry in through onFrame(), sync-write frames out
// through an injected write sink (no serial port needed). Expected bytes are written out by hand
// from docs/protocols.md, section 2.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::devices::body {
namespace {

using protocol::FrameFamily;
using Bytes = std::vector<uint8_t>;

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kRadPerTick = kTwoPi / 4096.0;

JointCalibration calibration(int zero, int direction, double velocity_scale = 0.0) {
  JointCalibration c;
  c.zero_ticks = zero;
  c.direction = direction;
  c.ticks_per_revolution = 4096;
  c.velocity_scale = velocity_scale;
  return c;
}

// --- JointCalibration ----------------------------------------------------------------------------

struct PositionCase {
  int zero;
  int direction;
  uint16_t ticks;
  double radians;
};

class BodyControllerCalibrationPosition : public testing::TestWithParam<PositionCase> {};

TEST_P(BodyControllerCalibrationPosition, TicksToRadiansAndBack) {
  const PositionCase& c = GetParam();
  const JointCalibration cal = calibration(c.zero, c.direction);
  EXPECT_NEAR(cal.toRadians(c.ticks), c.radians, 1e-12);
  const std::optional<uint16_t> ticks = cal.toTicks(c.radians);
  ASSERT_TRUE(ticks.has_value());
  EXPECT_EQ(*ticks, c.ticks);
}

INSTANTIATE_TEST_SUITE_P(BodyController, BodyControllerCalibrationPosition,
                         testing::Values(PositionCase{2048, 1, 2048, 0.0},
                                         PositionCase{2048, 1, 3072, M_PI / 2},
                                         PositionCase{2048, 1, 1024, -M_PI / 2},
                                         PositionCase{2048, -1, 3072, -M_PI / 2},
                                         PositionCase{2048, -1, 1024, M_PI / 2},
                                         PositionCase{0, 1, 4095, 4095 * kRadPerTick},
                                         PositionCase{1000, -1, 0, 1000 * kRadPerTick},
                                         PositionCase{2048, 1, 2049, kRadPerTick}));

TEST(BodyControllerCalibration, ToTicksRoundsToNearest) {
  const JointCalibration cal = calibration(2048, 1);
  EXPECT_EQ(cal.toTicks(0.4 * kRadPerTick), 2048);
  EXPECT_EQ(cal.toTicks(0.6 * kRadPerTick), 2049);
  EXPECT_EQ(cal.toTicks(-0.6 * kRadPerTick), 2047);
  const JointCalibration reversed = calibration(2048, -1);
  EXPECT_EQ(reversed.toTicks(0.6 * kRadPerTick), 2047);
  EXPECT_EQ(reversed.toTicks(-0.6 * kRadPerTick), 2049);
}

TEST(BodyControllerCalibration, ToTicksRefusesWhatTheServoCannotReach) {
  // 4096 ticks per turn: the servo takes 0..4095, never a clamped stand-in.
  const JointCalibration cal = calibration(2048, 1);
  EXPECT_EQ(cal.toTicks(-M_PI), 0);                  // exactly tick 0
  EXPECT_EQ(cal.toTicks(2047 * kRadPerTick), 4095);  // the highest tick
  EXPECT_FALSE(cal.toTicks(M_PI).has_value());       // 4096: one turn, not a position
  EXPECT_FALSE(cal.toTicks(4.0).has_value());        // 4655, the case of the review
  EXPECT_FALSE(cal.toTicks(-100.0).has_value());
  EXPECT_FALSE(calibration(2048, -1).toTicks(1000.0).has_value());
  const auto [low, high] = cal.reachableRadians();
  EXPECT_NEAR(low, -M_PI, 1e-12);
  EXPECT_NEAR(high, 2047 * kRadPerTick, 1e-12);
}

TEST(BodyControllerCalibration, ToTicksRejectsNanAndInfinity) {
  const JointCalibration cal = calibration(2048, 1);
  EXPECT_FALSE(cal.toTicks(std::numeric_limits<double>::quiet_NaN()).has_value());
  EXPECT_FALSE(cal.toTicks(std::numeric_limits<double>::infinity()).has_value());
  EXPECT_FALSE(cal.toTicks(-std::numeric_limits<double>::infinity()).has_value());
}

TEST(BodyControllerCalibration, VelocityFromTicksPerSecondWhenScaleIsZero) {
  EXPECT_NEAR(calibration(2048, 1).toRadiansPerSecond(-5), -5 * kRadPerTick, 1e-12);
  EXPECT_NEAR(calibration(2048, -1).toRadiansPerSecond(-5), 5 * kRadPerTick, 1e-12);
  EXPECT_NEAR(calibration(2048, 1).toRadiansPerSecond(4096), kTwoPi, 1e-12);
}

TEST(BodyControllerCalibration, VelocityUsesScaleWhenSet) {
  EXPECT_NEAR(calibration(2048, 1, 0.01).toRadiansPerSecond(-5), -0.05, 1e-12);
  EXPECT_NEAR(calibration(2048, -1, 0.01).toRadiansPerSecond(-5), 0.05, 1e-12);
  EXPECT_NEAR(calibration(2048, 1, 0.01).toRadiansPerSecond(10), 0.1, 1e-12);
}

// --- telemetry -----------------------------------------------------------------------------------

// Section 2b golden vector: N = 2, positions 2048, 1024, speeds 10, -5, IMU 1, -1, 16384, 0,
// 0, 100, 0, 0, -16384.
const Bytes& kTwoServosTelemetry = golden::body::kTelemetryTwoServos;

// N = 1 with the foot block (LEN = 40 + 4 = 0x2C): position 256, speed 0, IMU all zero, foot
// sensors little-endian: j0 = 01 02 -> 0x0201, j1 = 03 04 -> 0x0403, j7 = FF 00 -> 0x00FF.
// SUM = (0x2C + 01 + 01 + 02 + 03 + 04 + FF) mod 256 = 0x36.
const Bytes kFootTelemetryStill = {0x12, 0x34, 0x2C, 0x01, 0x00, 0x00, 0x00,              //
                                   0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //
                                   0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  //
                                   0x01, 0x02, 0x03, 0x04, 0x00, 0x00, 0x00, 0x00,        //
                                   0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xFF, 0x00, 0x36,
                                   0x1F, 0x2F};

std::vector<BodyJoint> twoJoints() {
  return {BodyJoint{"hip", 2, calibration(2048, 1)}, BodyJoint{"knee", 3, calibration(2048, 1)}};
}

struct Received {
  std::vector<Telemetry> frames;
  std::vector<core::Clock::time_point> arrivals;
};

BodyEvents recorder(Received* received) {
  return {[received](const Telemetry& telemetry, core::Clock::time_point arrival) {
    received->frames.push_back(telemetry);
    received->arrivals.push_back(arrival);
  }};
}

TEST(BodyControllerTelemetry, GoldenFrameReachesTheCallbackWithItsArrivalTime) {
  Received received;
  BodyController controller(twoJoints(), nullptr, recorder(&received));
  const core::Clock::time_point arrival = core::Clock::time_point(std::chrono::milliseconds(1234));
  controller.onFrame(kTelemetryFrames, kTwoServosTelemetry.data(), kTwoServosTelemetry.size(),
                     arrival);

  ASSERT_EQ(received.frames.size(), 1u);
  EXPECT_EQ(received.arrivals[0], arrival);
  const Telemetry& t = received.frames[0];
  ASSERT_EQ(t.servo_count, 2u);
  EXPECT_EQ(t.servos[0].position, 2048);
  EXPECT_EQ(t.servos[0].speed, 10);
  EXPECT_EQ(t.servos[1].position, 1024);
  EXPECT_EQ(t.servos[1].speed, -5);
  const std::array<int16_t, 9> imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  EXPECT_EQ(t.imu, imu);
  EXPECT_FALSE(t.has_foot);
  EXPECT_EQ(controller.stats().frames_decoded, 1u);
  EXPECT_EQ(controller.stats().decode_errors, 0u);
}

TEST(BodyControllerTelemetry, FootBlockIsLittleEndian) {
  Received received;
  BodyController controller({BodyJoint{"ankle", 7, calibration(2048, 1)}}, nullptr,
                            recorder(&received));
  controller.onFrame(kTelemetryFrames, kFootTelemetryStill.data(), kFootTelemetryStill.size(),
                     core::Clock::now());
  ASSERT_EQ(received.frames.size(), 1u);
  const Telemetry& t = received.frames[0];
  EXPECT_EQ(t.servos[0].position, 256);
  ASSERT_TRUE(t.has_foot);
  const std::array<uint16_t, 8> foot = {0x0201, 0x0403, 0, 0, 0, 0, 0, 0x00FF};
  EXPECT_EQ(t.foot, foot);
}

TEST(BodyControllerTelemetry, FrameOfAnotherServoCountIsADecodeError) {
  Received received;
  // Three joints configured: the two-servo golden frame has an impossible LEN for them.
  std::vector<BodyJoint> joints = twoJoints();
  joints.push_back(BodyJoint{"ankle", 4, calibration(2048, 1)});
  BodyController controller(joints, nullptr, recorder(&received));
  controller.onFrame(kTelemetryFrames, kTwoServosTelemetry.data(), kTwoServosTelemetry.size(),
                     core::Clock::now());
  EXPECT_TRUE(received.frames.empty());
  const BodyStats stats = controller.stats();
  EXPECT_EQ(stats.frames_decoded, 0u);
  EXPECT_EQ(stats.decode_errors, 1u);
  ASSERT_TRUE(stats.last_decode_error.has_value());
  EXPECT_EQ(*stats.last_decode_error, protocol::DecodeError::kBadLength);
}

TEST(BodyControllerTelemetry, OtherFamiliesOnASharedPortAreIgnored) {
  Received received;
  BodyController controller(twoJoints(), nullptr, recorder(&received));
  const Bytes& base_reset = golden::base::kResetSeq2;
  controller.onFrame(base::kFrames, base_reset.data(), base_reset.size(), core::Clock::now());
  // Even telemetry bytes under another family tag are not ours to decode.
  controller.onFrame(servo_bus::kResponseFrames, kTwoServosTelemetry.data(),
                     kTwoServosTelemetry.size(), core::Clock::now());
  EXPECT_TRUE(received.frames.empty());
  EXPECT_EQ(controller.stats().frames_decoded, 0u);
  EXPECT_EQ(controller.stats().decode_errors, 0u);
}

TEST(BodyControllerTelemetry, WorksWithoutACallback) {
  BodyController controller(twoJoints(), nullptr);
  controller.onFrame(kTelemetryFrames, kTwoServosTelemetry.data(), kTwoServosTelemetry.size(),
                     core::Clock::now());
  EXPECT_EQ(controller.stats().frames_decoded, 1u);
}

// --- joint commands ------------------------------------------------------------------------------

class BodyControllerCommand : public testing::Test {
 protected:
  core::FrameWriter sink() {
    return [this](const Bytes& frame) {
      written_.push_back(frame);
      return port_up_;
    };
  }

  std::vector<Bytes> written_;
  bool port_up_ = true;
  BodyController controller_{twoJoints(), sink()};
};

TEST_F(BodyControllerCommand, GoldenSyncWrite) {
  // hip (id 2) 0 rad -> 2048, knee (id 3) -pi/2 -> 1024 (docs/protocols.md, section 2a).
  const JointCommandResult result = controller_.sendJointCommand({"hip", "knee"}, {0.0, -M_PI / 2});
  EXPECT_TRUE(result.ok()) << result.message();
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                          0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68};
  ASSERT_EQ(written_.size(), 1u);
  EXPECT_EQ(written_[0], expected);
  EXPECT_EQ(controller_.stats().commands_sent, 1u);
}

TEST_F(BodyControllerCommand, FrameFollowsServoIdOrderNotMessageOrder) {
  ASSERT_TRUE(controller_.sendJointCommand({"knee", "hip"}, {-M_PI / 2, 0.0}).ok());
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                          0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x68};
  ASSERT_EQ(written_.size(), 1u);
  EXPECT_EQ(written_[0], expected);
}

TEST_F(BodyControllerCommand, NeverCommandedJointsAreLeftOut) {
  // Only knee (id 3) -> -pi/2 = 1024: LEN = 7 + 3 = 0x0A; CRC-16/BUYPASS worked out separately.
  ASSERT_TRUE(controller_.sendJointCommand({"knee"}, {-M_PI / 2}).ok());
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x83, 0x74,
                          0x00, 0x02, 0x00, 0x03, 0x00, 0x04, 0x05, 0x0E};
  ASSERT_EQ(written_.size(), 1u);
  EXPECT_EQ(written_[0], expected);
}

TEST_F(BodyControllerCommand, PartialCommandKeepsTheOtherJointsAtTheirLastPosition) {
  ASSERT_TRUE(controller_.sendJointCommand({"hip", "knee"}, {0.0, -M_PI / 2}).ok());
  // knee -> +pi/2 = 3072 = 00 0C little-endian; hip stays at 2048.
  ASSERT_TRUE(controller_.sendJointCommand({"knee"}, {M_PI / 2}).ok());
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                          0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x0C, 0x4A, 0xE8};
  ASSERT_EQ(written_.size(), 2u);
  EXPECT_EQ(written_[1], expected);
}

TEST_F(BodyControllerCommand, UnreachableJointIsLeftOutAndTheOthersAreSent) {
  // hip 4.0 rad would be tick 4655: left out; knee -pi/2 = 1024 goes alone (frame as above).
  const JointCommandResult result = controller_.sendJointCommand({"hip", "knee"}, {4.0, -M_PI / 2});
  EXPECT_TRUE(result.ok()) << result.message();
  ASSERT_EQ(result.out_of_range.size(), 1u);
  EXPECT_NE(result.message().find("hip: 4.000 rad is outside -3.142 .. 3.140 rad"),
            std::string::npos)
      << result.message();
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x83, 0x74,
                          0x00, 0x02, 0x00, 0x03, 0x00, 0x04, 0x05, 0x0E};
  ASSERT_EQ(written_.size(), 1u);
  EXPECT_EQ(written_[0], expected);
  EXPECT_EQ(controller_.stats().joints_out_of_range, 1u);
}

TEST_F(BodyControllerCommand, CommandWithOnlyUnreachableJointsWritesNothing) {
  const JointCommandResult result = controller_.sendJointCommand({"hip"}, {-4.0});
  EXPECT_EQ(result.status, JointCommandStatus::kOutOfRange);
  EXPECT_TRUE(written_.empty());
  EXPECT_EQ(controller_.stats().commands_rejected, 1u);
  EXPECT_EQ(controller_.stats().joints_out_of_range, 1u);
}

TEST_F(BodyControllerCommand, UnknownJointIsRejectedByNameAndWritesNothing) {
  const JointCommandResult result = controller_.sendJointCommand({"hip", "elbow"}, {0.0, 0.0});
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(result.status, JointCommandStatus::kUnknownJoint);
  EXPECT_EQ(result.joint, "elbow");
  EXPECT_NE(result.message().find("elbow"), std::string::npos);
  EXPECT_TRUE(written_.empty());
  EXPECT_EQ(controller_.stats().commands_rejected, 1u);
  EXPECT_EQ(controller_.stats().commands_sent, 0u);
}

TEST_F(BodyControllerCommand, LengthMismatchIsRejected) {
  EXPECT_EQ(controller_.sendJointCommand({"hip", "knee"}, {0.0}).status,
            JointCommandStatus::kLengthMismatch);
  EXPECT_EQ(controller_.sendJointCommand({"hip"}, {}).status, JointCommandStatus::kLengthMismatch);
  EXPECT_TRUE(written_.empty());
  EXPECT_EQ(controller_.stats().commands_rejected, 2u);
}

TEST_F(BodyControllerCommand, NonFinitePositionsAreRejectedByName) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  JointCommandResult result = controller_.sendJointCommand({"hip", "knee"}, {0.0, nan});
  EXPECT_EQ(result.status, JointCommandStatus::kNotFinite);
  EXPECT_EQ(result.joint, "knee");
  EXPECT_NE(result.message().find("knee"), std::string::npos);
  result = controller_.sendJointCommand({"hip"}, {-inf});
  EXPECT_EQ(result.status, JointCommandStatus::kNotFinite);
  EXPECT_EQ(result.joint, "hip");
  EXPECT_TRUE(written_.empty());
}

TEST_F(BodyControllerCommand, EmptyAndDuplicateCommandsAreRejected) {
  EXPECT_EQ(controller_.sendJointCommand({}, {}).status, JointCommandStatus::kEmpty);
  const JointCommandResult result = controller_.sendJointCommand({"hip", "hip"}, {0.0, 1.0});
  EXPECT_EQ(result.status, JointCommandStatus::kDuplicateJoint);
  EXPECT_EQ(result.joint, "hip");
  EXPECT_TRUE(written_.empty());
}

// A name given twice is a duplicate whatever its values: an out-of-range (left out) or non-finite
// first occurrence must not hide the second one.
TEST_F(BodyControllerCommand, DuplicateIsRejectedWhateverTheValues) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    std::vector<std::string> names;
    std::vector<double> positions;
  };
  const std::vector<Case> cases = {
      {{"hip", "hip"}, {4.0, 0.0}},                // first out of range, second valid
      {{"hip", "hip"}, {0.0, 4.0}},                // first valid, second out of range
      {{"hip", "hip"}, {4.0, -4.0}},               // both out of range
      {{"knee", "hip", "hip"}, {0.0, 4.0, nan}},   // out of range, then not finite
      {{"hip", "knee", "hip"}, {-4.0, 0.0, 0.5}},  // another joint between them
  };
  std::size_t rejected = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::PrintToString(c.names) + " " + ::testing::PrintToString(c.positions));
    const JointCommandResult result = controller_.sendJointCommand(c.names, c.positions);
    EXPECT_FALSE(result.ok());
    EXPECT_EQ(result.status, JointCommandStatus::kDuplicateJoint);
    EXPECT_EQ(result.joint, "hip");
    EXPECT_NE(result.message().find("hip"), std::string::npos) << result.message();
    EXPECT_EQ(controller_.stats().commands_rejected, ++rejected);
  }
  EXPECT_TRUE(written_.empty()) << "a rejected command wrote a frame";
  EXPECT_EQ(controller_.stats().commands_sent, 0u);
}

TEST_F(BodyControllerCommand, RejectedCommandDoesNotChangeStoredPositions) {
  ASSERT_TRUE(controller_.sendJointCommand({"hip", "knee"}, {0.0, -M_PI / 2}).ok());
  // hip's valid value comes before the NaN: it must not be stored either.
  EXPECT_FALSE(controller_.sendJointCommand({"hip", "knee"}, {1.0, std::nan("")}).ok());
  ASSERT_TRUE(controller_.sendJointCommand({"knee"}, {M_PI / 2}).ok());
  const Bytes expected = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                          0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x0C, 0x4A, 0xE8};
  ASSERT_EQ(written_.size(), 2u);
  EXPECT_EQ(written_[1], expected);
}

TEST_F(BodyControllerCommand, RefusedWriteIsReportedAndCounted) {
  port_up_ = false;
  const JointCommandResult result = controller_.sendJointCommand({"hip"}, {0.0});
  EXPECT_EQ(result.status, JointCommandStatus::kWriteFailed);
  EXPECT_EQ(written_.size(), 1u);
  const BodyStats stats = controller_.stats();
  EXPECT_EQ(stats.write_failures, 1u);
  EXPECT_EQ(stats.commands_sent, 0u);
  EXPECT_EQ(stats.commands_rejected, 0u);
}

// An e-stop voids everything accepted before it: a command accepted before an e-stop and written
// after its release is dropped, said and counted; one accepted after the release goes out.
TEST_F(BodyControllerCommand, ACommandAcceptedBeforeAnEStopIsVoidedEvenAfterTheRelease) {
  const core::MotionGate::Generation accepted = controller_.gate().generation();
  controller_.gate().setLocked(true);
  controller_.gate().setLocked(false);
  const JointCommandResult result = controller_.sendJointCommand({"hip"}, {0.0}, accepted);
  EXPECT_EQ(result.status, JointCommandStatus::kMotionVoided);
  EXPECT_EQ(result.message(),
            "joint command not written: e-stop engaged after this command was accepted");
  EXPECT_TRUE(written_.empty());
  EXPECT_EQ(controller_.stats().motion_refused, 1u);
  EXPECT_EQ(controller_.stats().motion_voided, 1u);
  EXPECT_EQ(controller_.gate().refusedAtWrite(), 1u);
  EXPECT_FALSE(controller_.lastCommandedPosition(0)) << "nothing stored for a voided command";

  const core::MotionGate::Generation fresh = controller_.gate().generation();
  EXPECT_TRUE(controller_.sendJointCommand({"hip"}, {0.0}, fresh).ok());
  EXPECT_TRUE(controller_.sendJointCommand({"hip"}, {0.1}).ok()) << "unset: accepted now";
  EXPECT_EQ(written_.size(), 2u);
}

TEST_F(BodyControllerCommand, AWrittenCommandCountsAsMotionForAWhile) {
  EXPECT_EQ(controller_.motionInForce(core::Clock::now()), "") << "never commanded";
  ASSERT_TRUE(controller_.sendJointCommand({"hip"}, {0.0}).ok());
  const core::Clock::time_point now = core::Clock::now();
  EXPECT_EQ(controller_.motionInForce(now).rfind("joint command written 0.", 0), 0u)
      << controller_.motionInForce(now);
  EXPECT_EQ(controller_.motionInForce(now + BodyController::kJointCommandMotion), "");
  controller_.gate().setLocked(true);
  ASSERT_FALSE(controller_.sendJointCommand({"hip"}, {0.2}).ok());
  EXPECT_EQ(controller_.motionInForce(now + BodyController::kJointCommandMotion), "")
      << "a refused command moves nothing";
}

TEST(BodyControllerCommandNoSink, MissingWriterIsAWriteFailure) {
  BodyController controller(twoJoints(), nullptr);
  EXPECT_EQ(controller.sendJointCommand({"hip"}, {0.0}).status, JointCommandStatus::kWriteFailed);
}

}  // namespace
}  // namespace serial_robot_driver::devices::body
