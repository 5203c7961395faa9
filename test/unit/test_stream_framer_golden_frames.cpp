// StreamFramer: its configuration per side, and every golden frame alone (whole, byte by byte,
// with its family disabled).
#include <gtest/gtest.h>

#include "support/stream_framer_recording.h"

namespace serial_robot_driver::protocol {
namespace {

using namespace stream_framer_test;  // NOLINT: the shared fixture

// --- small pieces ------------------------------------------------------------------------------

TEST(StreamFramerConfig, ToStringNamesEveryFamily) {
  EXPECT_STREQ(toString(FrameFamily::kBase), "base");
  EXPECT_STREQ(toString(FrameFamily::kTelemetry), "telemetry");
  EXPECT_STREQ(toString(FrameFamily::kServoResponse), "servo_response");
  EXPECT_STREQ(toString(FrameFamily::kServoRequest), "servo_request");
  EXPECT_STREQ(toString(FrameFamily::kSyncWrite), "sync_write");
}

TEST(StreamFramerConfig, ForDriverEnablesWhatTheDevicesSend) {
  const FramerConfig all = FramerConfig::forDriver(true, true, true, 7);
  EXPECT_TRUE(all.base);
  EXPECT_TRUE(all.telemetry);
  EXPECT_TRUE(all.servo_response);
  EXPECT_TRUE(all.servo_request);  // the half-duplex echo of our own requests
  EXPECT_FALSE(all.sync_write);
  EXPECT_EQ(all.telemetry_servo_count, 7u);

  const FramerConfig body_only = FramerConfig::forDriver(false, true, false, 2);
  EXPECT_FALSE(body_only.base);
  EXPECT_TRUE(body_only.telemetry);
  EXPECT_FALSE(body_only.servo_response);
  EXPECT_FALSE(body_only.servo_request);

  const FramerConfig bus_only = FramerConfig::forDriver(false, false, true, 0);
  EXPECT_FALSE(bus_only.base);
  EXPECT_FALSE(bus_only.telemetry);
  EXPECT_TRUE(bus_only.servo_response);
  EXPECT_TRUE(bus_only.servo_request);
}

TEST(StreamFramerConfig, ForSimulatorEnablesWhatTheHostSends) {
  const FramerConfig config = FramerConfig::forSimulator();
  EXPECT_TRUE(config.base);
  EXPECT_FALSE(config.telemetry);
  EXPECT_FALSE(config.servo_response);
  EXPECT_TRUE(config.servo_request);
  EXPECT_TRUE(config.sync_write);
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
  FramerConfig config = allFamilies();
  switch (GetParam().family) {
    case FrameFamily::kBase:
      config.base = false;
      break;
    case FrameFamily::kTelemetry:
      config.telemetry = false;
      break;
    case FrameFamily::kServoResponse:
      config.servo_response = false;
      break;
    case FrameFamily::kServoRequest:
      config.servo_request = false;
      break;
    case FrameFamily::kSyncWrite:
      config.sync_write = false;
      break;
  }
  RecordingFramer framer(config);
  framer.feed(GetParam().bytes);
  EXPECT_TRUE(framer.frames().empty());
  EXPECT_EQ(framer.stats().bytes_skipped, GetParam().bytes.size());
  EXPECT_EQ(errorCount(framer.stats()), 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

INSTANTIATE_TEST_SUITE_P(
    StreamFramerVectors, StreamFramerGolden,
    ::testing::Values(GoldenCase{"BaseReset", kBaseReset, FrameFamily::kBase},
                      GoldenCase{"BaseBatteryRequest", kBaseBatteryRequest, FrameFamily::kBase},
                      GoldenCase{"BaseClearEncoders", kBaseClearEncoders, FrameFamily::kBase},
                      GoldenCase{"BaseLeft4", kBaseLeft4, FrameFamily::kBase},
                      GoldenCase{"BaseRight4", kBaseRight4, FrameFamily::kBase},
                      GoldenCase{"BaseBoth4", kBaseBoth4, FrameFamily::kBase},
                      GoldenCase{"BaseBothMinus6", kBaseBothMinus6, FrameFamily::kBase},
                      GoldenCase{"BaseBatteryReply", kBaseBatteryReply, FrameFamily::kBase},
                      GoldenCase{"BaseErrorStatus", kBaseErrorStatus, FrameFamily::kBase},
                      GoldenCase{"BaseLen1", kBaseLen1, FrameFamily::kBase},
                      GoldenCase{"Telemetry", kTelemetry, FrameFamily::kTelemetry},
                      GoldenCase{"TelemetryFoot", kTelemetryFoot, FrameFamily::kTelemetry},
                      GoldenCase{"SyncWrite", kSyncWrite, FrameFamily::kSyncWrite},
                      GoldenCase{"SyncWriteEmpty", kSyncWriteEmpty, FrameFamily::kSyncWrite},
                      GoldenCase{"ServoPing", kServoPing, FrameFamily::kServoRequest},
                      GoldenCase{"ServoRotate", kServoRotate, FrameFamily::kServoRequest},
                      GoldenCase{"ServoReadAngle", kServoReadAngle, FrameFamily::kServoRequest},
                      GoldenCase{"ServoSpinCcw", kServoSpinCcw, FrameFamily::kServoRequest},
                      GoldenCase{"ServoSpinStop", kServoSpinStop, FrameFamily::kServoRequest},
                      GoldenCase{"ServoSpinTurns", kServoSpinTurns, FrameFamily::kServoRequest},
                      GoldenCase{"ServoSpinMs", kServoSpinMs, FrameFamily::kServoRequest},
                      GoldenCase{"ServoDamping", kServoDamping, FrameFamily::kServoRequest},
                      GoldenCase{"ServoPingReply", kServoPingReply, FrameFamily::kServoResponse},
                      GoldenCase{"ServoReadAngleReply", kServoReadAngleReply,
                                 FrameFamily::kServoResponse},
                      GoldenCase{"ServoEmptyReply", kServoEmptyReply, FrameFamily::kServoResponse}),
    [](const ::testing::TestParamInfo<GoldenCase>& info) { return info.param.name; });

}  // namespace
}  // namespace serial_robot_driver::protocol
