// StreamFramer: its configuration per side, and every golden frame alone (whole, byte by byte,
// with its family disabled).
#include <gtest/gtest.h>

#include "support/framer_configs.h"
#include "support/stream_framer_recording.h"

namespace serial_robot_driver::protocol {
namespace {

using namespace stream_framer_test;  // NOLINT: the shared fixture

// --- small pieces ------------------------------------------------------------------------------

TEST(StreamFramerConfig, EveryFamilyHasItsName) {
  EXPECT_STREQ(protocol::base::kFrames.name, "base");
  EXPECT_STREQ(protocol::body::kTelemetryFrames.name, "telemetry");
  EXPECT_STREQ(protocol::servo::kResponseFrames.name, "servo_response");
  EXPECT_STREQ(protocol::servo::kRequestFrames.name, "servo_request");
  EXPECT_STREQ(protocol::body::kSyncWriteFrames.name, "sync_write");
}

TEST(StreamFramerConfig, ForDriverEnablesWhatTheDevicesSend) {
  const FramerConfig all = test_support::driverFramer({"base", "body", "servo_bus"}, 7);
  EXPECT_TRUE(all.accepts(base::kFrames));
  EXPECT_TRUE(all.accepts(body::kTelemetryFrames));
  EXPECT_TRUE(all.accepts(servo::kResponseFrames));
  EXPECT_TRUE(all.accepts(servo::kRequestFrames));  // the half-duplex echo of our own requests
  EXPECT_FALSE(all.accepts(body::kSyncWriteFrames));
  EXPECT_EQ(all.expectedOf(body::kTelemetryFrames), 7u);

  const FramerConfig body_only = test_support::driverFramer({"body"}, 2);
  EXPECT_FALSE(body_only.accepts(base::kFrames));
  EXPECT_TRUE(body_only.accepts(body::kTelemetryFrames));
  EXPECT_FALSE(body_only.accepts(servo::kResponseFrames));
  EXPECT_FALSE(body_only.accepts(servo::kRequestFrames));

  const FramerConfig bus_only = test_support::driverFramer({"servo_bus"});
  EXPECT_FALSE(bus_only.accepts(base::kFrames));
  EXPECT_FALSE(bus_only.accepts(body::kTelemetryFrames));
  EXPECT_TRUE(bus_only.accepts(servo::kResponseFrames));
  EXPECT_TRUE(bus_only.accepts(servo::kRequestFrames));
}

TEST(StreamFramerConfig, ForSimulatorEnablesWhatTheHostSends) {
  const FramerConfig config = test_support::simulatorFramer();
  EXPECT_TRUE(config.accepts(base::kFrames));
  EXPECT_FALSE(config.accepts(body::kTelemetryFrames));
  EXPECT_FALSE(config.accepts(servo::kResponseFrames));
  EXPECT_TRUE(config.accepts(servo::kRequestFrames));
  EXPECT_TRUE(config.accepts(body::kSyncWriteFrames));
}

// --- every golden frame, alone
// ---------------------------------------------------------------------

struct GoldenCase {
  std::string name;
  Bytes bytes;
  FrameFamily family;
};
void PrintTo(const GoldenCase& c, std::ostream* os) { *os << c.name; }

class StreamFramerGolden : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(StreamFramerGolden, WholeFrameIsEmittedOnce) {
  RecordingFramer framer(allFamilies());
  framer.feed(GetParam().bytes);
  ASSERT_EQ(framer.frames().size(), 1u);
  EXPECT_EQ(framer.frames()[0], (Frame{GetParam().family, GetParam().bytes}));
  EXPECT_EQ(frameCount(framer.stats(), GetParam().family), 1u);
  EXPECT_EQ(framer.stats().bytes_in, GetParam().bytes.size());
  EXPECT_EQ(framer.stats().bytes_skipped, 0u);
  EXPECT_EQ(errorCount(framer.stats()), 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST_P(StreamFramerGolden, ByteByByteEmitsOnlyAfterTheLastByte) {
  RecordingFramer framer(allFamilies());
  const Bytes& bytes = GetParam().bytes;
  for (std::size_t i = 0; i + 1 < bytes.size(); ++i) {
    framer.framer().feed(&bytes[i], 1);
    EXPECT_EQ(framer.framer().buffered(), i + 1);
  }
  EXPECT_TRUE(framer.frames().empty());
  framer.framer().feed(&bytes.back(), 1);
  ASSERT_EQ(framer.frames().size(), 1u);
  EXPECT_EQ(framer.frames()[0], (Frame{GetParam().family, bytes}));
  EXPECT_EQ(framer.stats().bytes_skipped, 0u);
}

TEST_P(StreamFramerGolden, IgnoredWhenItsFamilyIsDisabled) {
  // Every family but the frame's own.
  const FramerConfig all = allFamilies();
  FramerConfig config;
  for (std::size_t i = 0; i < all.family_count; ++i) {
    if (!(all.families[i].family == GetParam().family)) {
      config.accept(all.families[i].family, all.families[i].expected);
    }
  }
  ASSERT_EQ(config.family_count + 1, all.family_count);
  RecordingFramer framer(config);
  framer.feed(GetParam().bytes);
  EXPECT_TRUE(framer.frames().empty());
  EXPECT_EQ(framer.stats().bytes_skipped, GetParam().bytes.size());
  EXPECT_EQ(errorCount(framer.stats()), 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

INSTANTIATE_TEST_SUITE_P(
    StreamFramerVectors, StreamFramerGolden,
    ::testing::Values(
        GoldenCase{"BaseReset", kBaseReset, protocol::base::kFrames},
        GoldenCase{"BaseBatteryRequest", kBaseBatteryRequest, protocol::base::kFrames},
        GoldenCase{"BaseClearEncoders", kBaseClearEncoders, protocol::base::kFrames},
        GoldenCase{"BaseLeft4", kBaseLeft4, protocol::base::kFrames},
        GoldenCase{"BaseRight4", kBaseRight4, protocol::base::kFrames},
        GoldenCase{"BaseBoth4", kBaseBoth4, protocol::base::kFrames},
        GoldenCase{"BaseBothMinus6", kBaseBothMinus6, protocol::base::kFrames},
        GoldenCase{"BaseBatteryReply", kBaseBatteryReply, protocol::base::kFrames},
        GoldenCase{"BaseErrorStatus", kBaseErrorStatus, protocol::base::kFrames},
        GoldenCase{"BaseLen1", kBaseLen1, protocol::base::kFrames},
        GoldenCase{"Telemetry", kTelemetry, protocol::body::kTelemetryFrames},
        GoldenCase{"TelemetryFoot", kTelemetryFoot, protocol::body::kTelemetryFrames},
        GoldenCase{"SyncWrite", kSyncWrite, protocol::body::kSyncWriteFrames},
        GoldenCase{"SyncWriteEmpty", kSyncWriteEmpty, protocol::body::kSyncWriteFrames},
        GoldenCase{"ServoPing", kServoPing, protocol::servo::kRequestFrames},
        GoldenCase{"ServoRotate", kServoRotate, protocol::servo::kRequestFrames},
        GoldenCase{"ServoReadAngle", kServoReadAngle, protocol::servo::kRequestFrames},
        GoldenCase{"ServoSpinCcw", kServoSpinCcw, protocol::servo::kRequestFrames},
        GoldenCase{"ServoSpinStop", kServoSpinStop, protocol::servo::kRequestFrames},
        GoldenCase{"ServoSpinTurns", kServoSpinTurns, protocol::servo::kRequestFrames},
        GoldenCase{"ServoSpinMs", kServoSpinMs, protocol::servo::kRequestFrames},
        GoldenCase{"ServoDamping", kServoDamping, protocol::servo::kRequestFrames},
        GoldenCase{"ServoPingReply", kServoPingReply, protocol::servo::kResponseFrames},
        GoldenCase{"ServoReadAngleReply", kServoReadAngleReply, protocol::servo::kResponseFrames},
        GoldenCase{"ServoEmptyReply", kServoEmptyReply, protocol::servo::kResponseFrames}),
    [](const ::testing::TestParamInfo<GoldenCase>& info) { return info.param.name; });

}  // namespace
}  // namespace serial_robot_driver::protocol
