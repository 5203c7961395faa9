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
  EXPECT_STREQ(devices::base::kFrames.name, "base");
  EXPECT_STREQ(devices::body::kTelemetryFrames.name, "telemetry");
  EXPECT_STREQ(devices::servo_bus::kResponseFrames.name, "servo_response");
  EXPECT_STREQ(devices::servo_bus::kRequestFrames.name, "servo_request");
  EXPECT_STREQ(devices::body::kSyncWriteFrames.name, "sync_write");
}

TEST(StreamFramerConfig, ForDriverEnablesWhatTheDevicesSend) {
  const FramerConfig all = test_support::driverFramer({"base", "body", "servo_bus"}, 7);
  EXPECT_TRUE(all.accepts(devices::base::kFrames));
  EXPECT_TRUE(all.accepts(devices::body::kTelemetryFrames));
  EXPECT_TRUE(all.accepts(devices::servo_bus::kResponseFrames));
  EXPECT_TRUE(
      all.accepts(devices::servo_bus::kRequestFrames));  // the half-duplex echo of our own requests
  EXPECT_FALSE(all.accepts(devices::body::kSyncWriteFrames));
  EXPECT_EQ(all.expectedOf(devices::body::kTelemetryFrames), 7u);

  const FramerConfig body_only = test_support::driverFramer({"body"}, 2);
  EXPECT_FALSE(body_only.accepts(devices::base::kFrames));
  EXPECT_TRUE(body_only.accepts(devices::body::kTelemetryFrames));
  EXPECT_FALSE(body_only.accepts(devices::servo_bus::kResponseFrames));
  EXPECT_FALSE(body_only.accepts(devices::servo_bus::kRequestFrames));

  const FramerConfig bus_only = test_support::driverFramer({"servo_bus"});
  EXPECT_FALSE(bus_only.accepts(devices::base::kFrames));
  EXPECT_FALSE(bus_only.accepts(devices::body::kTelemetryFrames));
  EXPECT_TRUE(bus_only.accepts(devices::servo_bus::kResponseFrames));
  EXPECT_TRUE(bus_only.accepts(devices::servo_bus::kRequestFrames));
}

TEST(StreamFramerConfig, ForSimulatorEnablesWhatTheHostSends) {
  const FramerConfig config = test_support::simulatorFramer();
  EXPECT_TRUE(config.accepts(devices::base::kFrames));
  EXPECT_FALSE(config.accepts(devices::body::kTelemetryFrames));
  EXPECT_FALSE(config.accepts(devices::servo_bus::kResponseFrames));
  EXPECT_TRUE(config.accepts(devices::servo_bus::kRequestFrames));
  EXPECT_TRUE(config.accepts(devices::body::kSyncWriteFrames));
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
        GoldenCase{"BaseReset", kBaseReset, devices::base::kFrames},
        GoldenCase{"BaseBatteryRequest", kBaseBatteryRequest, devices::base::kFrames},
        GoldenCase{"BaseClearEncoders", kBaseClearEncoders, devices::base::kFrames},
        GoldenCase{"BaseLeft4", kBaseLeft4, devices::base::kFrames},
        GoldenCase{"BaseRight4", kBaseRight4, devices::base::kFrames},
        GoldenCase{"BaseBoth4", kBaseBoth4, devices::base::kFrames},
        GoldenCase{"BaseBothMinus6", kBaseBothMinus6, devices::base::kFrames},
        GoldenCase{"BaseBatteryReply", kBaseBatteryReply, devices::base::kFrames},
        GoldenCase{"BaseErrorStatus", kBaseErrorStatus, devices::base::kFrames},
        GoldenCase{"BaseLen1", kBaseLen1, devices::base::kFrames},
        GoldenCase{"Telemetry", kTelemetry, devices::body::kTelemetryFrames},
        GoldenCase{"TelemetryFoot", kTelemetryFoot, devices::body::kTelemetryFrames},
        GoldenCase{"SyncWrite", kSyncWrite, devices::body::kSyncWriteFrames},
        GoldenCase{"SyncWriteEmpty", kSyncWriteEmpty, devices::body::kSyncWriteFrames},
        GoldenCase{"ServoPing", kServoPing, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoRotate", kServoRotate, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoReadAngle", kServoReadAngle, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoSpinCcw", kServoSpinCcw, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoSpinStop", kServoSpinStop, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoSpinTurns", kServoSpinTurns, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoSpinMs", kServoSpinMs, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoDamping", kServoDamping, devices::servo_bus::kRequestFrames},
        GoldenCase{"ServoPingReply", kServoPingReply, devices::servo_bus::kResponseFrames},
        GoldenCase{"ServoReadAngleReply", kServoReadAngleReply,
                   devices::servo_bus::kResponseFrames},
        GoldenCase{"ServoEmptyReply", kServoEmptyReply, devices::servo_bus::kResponseFrames}),
    [](const ::testing::TestParamInfo<GoldenCase>& info) { return info.param.name; });

}  // namespace
}  // namespace serial_robot_driver::protocol
