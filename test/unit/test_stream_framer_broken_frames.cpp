// StreamFramer on broken and truncated frames: counted, skipped, and the next frame still comes
// through.
#include <gtest/gtest.h>

#include "support/stream_framer_recording.h"

namespace serial_robot_driver::protocol {
namespace {

using namespace stream_framer_test;  // NOLINT: the shared fixture

// --- broken frames followed by a good one --------------------------------------------------------

struct BrokenCase {
  std::string name;
  Bytes broken;
  uint64_t checksum_errors;
  uint64_t bad_tails;
  uint64_t bad_lengths;
  uint64_t unknown_commands = 0;
};
void PrintTo(const BrokenCase& c, std::ostream* os) { *os << c.name; }

class StreamFramerBroken : public ::testing::TestWithParam<BrokenCase> {};

TEST_P(StreamFramerBroken, CountedSkippedAndTheNextFrameStillComesThrough) {
  const BrokenCase& c = GetParam();
  for (const Frame& good : {Frame{devices::servo_bus::kResponseFrames, kServoPingReply},
                            Frame{devices::base::kFrames, kBaseBatteryReply},
                            Frame{devices::body::kSyncWriteFrames, kSyncWrite}}) {
    SCOPED_TRACE(good.family.name);
    RecordingFramer framer(allFamilies());
    framer.feed(concat({c.broken, good.bytes}));
    ASSERT_EQ(framer.frames().size(), 1u);
    EXPECT_EQ(framer.frames()[0], good);
    EXPECT_EQ(framer.stats().checksum_errors, c.checksum_errors);
    EXPECT_EQ(framer.stats().bad_tails, c.bad_tails);
    EXPECT_EQ(framer.stats().bad_lengths, c.bad_lengths);
    EXPECT_EQ(framer.stats().unknown_commands, c.unknown_commands);
    EXPECT_EQ(framer.stats().bytes_skipped, c.broken.size());
    EXPECT_EQ(framer.framer().buffered(), 0u);
    expectBytesAccountedFor(framer, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(
    StreamFramerBadChecksum, StreamFramerBroken,
    ::testing::Values(
        BrokenCase{"Base", {0x55, 0xAA, 0x02, 0x02, 0x05, 0x00, 0xFB}, 1, 0, 0},
        BrokenCase{"Telemetry",
                   {0x12, 0x34, 0x20, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB,
                    0x00, 0x01, 0xFF, 0xFF, 0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                    0x64, 0x00, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x94, 0x1F, 0x2F},
                   1,
                   0,
                   0},
        BrokenCase{"ServoRequest", {0x12, 0x4C, 0x01, 0x01, 0x03, 0x64}, 1, 0, 0},
        BrokenCase{"ServoResponse", {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x86, 0x03, 0xB8}, 1, 0, 0},
        BrokenCase{"SyncWriteCrcLow",
                   {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                    0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x78, 0x68},
                   1,
                   0,
                   0},
        BrokenCase{"SyncWriteCrcHigh",
                   {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                    0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x04, 0x79, 0x69},
                   1,
                   0,
                   0},
        // The vendor's erratum (03 00 40 instead of 03 00 04) must fail the CRC.
        BrokenCase{"SyncWriteVendorErratum",
                   {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                    0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x40, 0x79, 0x68},
                   1,
                   0,
                   0}),
    [](const ::testing::TestParamInfo<BrokenCase>& info) { return info.param.name; });

INSTANTIATE_TEST_SUITE_P(
    StreamFramerBadTail, StreamFramerBroken,
    ::testing::Values(BrokenCase{"Tail1E2F",
                                 {0x12, 0x34, 0x20, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB,
                                  0x00, 0x01, 0xFF, 0xFF, 0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                  0x64, 0x00, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x93, 0x1E, 0x2F},
                                 0,
                                 1,
                                 0},
                      BrokenCase{"Tail1F2E",
                                 {0x12, 0x34, 0x20, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB,
                                  0x00, 0x01, 0xFF, 0xFF, 0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                  0x64, 0x00, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x93, 0x1F, 0x2E},
                                 0,
                                 1,
                                 0}),
    [](const ::testing::TestParamInfo<BrokenCase>& info) { return info.param.name; });

// Impossible LEN bytes: the framer must reject them from the header alone, without waiting for
// LEN bytes. (Base LEN 1/2/5 and servo N 0/1/2/5 are legal; see the golden table.)
INSTANTIATE_TEST_SUITE_P(
    StreamFramerBadLength, StreamFramerBroken,
    ::testing::Values(
        BrokenCase{"BaseLen0", {0x55, 0xAA, 0x00}, 0, 0, 1},
        BrokenCase{"BaseLen33", {0x55, 0xAA, 0x21}, 0, 0, 1},
        BrokenCase{"BaseLen255", {0x55, 0xAA, 0xFF}, 0, 0, 1},
        BrokenCase{"TelemetryLen0", {0x12, 0x34, 0x00}, 0, 0, 1},
        BrokenCase{"TelemetryLen1", {0x12, 0x34, 0x01}, 0, 0, 1},
        BrokenCase{"TelemetryLen2", {0x12, 0x34, 0x02}, 0, 0, 1},
        BrokenCase{"TelemetryLen5", {0x12, 0x34, 0x05}, 0, 0, 1},
        BrokenCase{"TelemetryLen31", {0x12, 0x34, 0x1F}, 0, 0, 1},
        BrokenCase{"TelemetryLen36", {0x12, 0x34, 0x24}, 0, 0, 1},
        BrokenCase{"TelemetryLen255", {0x12, 0x34, 0xFF}, 0, 0, 1},
        BrokenCase{"ServoResponseN34", {0x05, 0x1C, 0x05, 0x22}, 0, 0, 1},
        BrokenCase{"ServoResponseN255", {0x05, 0x1C, 0x01, 0xFF}, 0, 0, 1},
        // An unknown CMD has its own counter, not "bad length".
        BrokenCase{"ServoResponseCmd0", {0x05, 0x1C, 0x00, 0x01}, 0, 0, 0, 1},
        BrokenCase{"ServoResponseCmd17", {0x05, 0x1C, 0x11, 0x01}, 0, 0, 0, 1},
        BrokenCase{"ServoRequestN255", {0x12, 0x4C, 0x01, 0xFF}, 0, 0, 1},
        BrokenCase{"ServoRequestCmd255", {0x12, 0x4C, 0xFF, 0x01}, 0, 0, 0, 1},
        BrokenCase{"SyncWriteLen0", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x00, 0x00}, 0, 0, 1},
        BrokenCase{"SyncWriteLen1", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x01, 0x00}, 0, 0, 1},
        BrokenCase{"SyncWriteLen2", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x02, 0x00}, 0, 0, 1},
        BrokenCase{"SyncWriteLen5", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x05, 0x00}, 0, 0, 1},
        BrokenCase{"SyncWriteLen11", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0B, 0x00}, 0, 0, 1},
        BrokenCase{"SyncWriteLen255", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0xFF, 0x00}, 0, 0, 1},
        // 7 + 3 * 65: one servo more than kMaxSyncWriteServos.
        BrokenCase{"SyncWrite65Servos", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0xCA, 0x00}, 0, 0, 1},
        BrokenCase{"SyncWriteLen65535", {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0xFF, 0xFF}, 0, 0, 1}),
    [](const ::testing::TestParamInfo<BrokenCase>& info) { return info.param.name; });

// --- truncated frames ----------------------------------------------------------------------------

struct TruncatedCase {
  std::string name;
  Bytes full;
  std::size_t kept;  ///< bytes of `full` that arrive before the next frames
};
void PrintTo(const TruncatedCase& c, std::ostream* os) { *os << c.name; }

class StreamFramerTruncated : public ::testing::TestWithParam<TruncatedCase> {};

TEST_P(StreamFramerTruncated, FollowingFramesStillComeThrough) {
  const TruncatedCase& c = GetParam();
  const Bytes truncated(c.full.begin(), c.full.begin() + c.kept);
  // Enough good frames after it to complete (and so disprove) the truncated candidate.
  const Bytes followers = concat({kServoPingReply, kBaseBatteryReply, kServoPingReply,
                                  kBaseBatteryReply, kServoPingReply, kBaseBatteryReply});
  std::mt19937 rng(7);
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(concat({truncated, followers, kTelemetry}), &rng, 16);
  ASSERT_EQ(framer.frames().size(), 7u);
  EXPECT_EQ(framer.frames()[0], (Frame{devices::servo_bus::kResponseFrames, kServoPingReply}));
  EXPECT_EQ(framer.frames()[5], (Frame{devices::base::kFrames, kBaseBatteryReply}));
  EXPECT_EQ(framer.frames()[6], (Frame{devices::body::kTelemetryFrames, kTelemetry}));
  EXPECT_EQ(framer.stats().bytes_skipped, truncated.size());
  // The truncated candidate failed exactly once (which check fails depends on the bytes after it).
  EXPECT_EQ(errorCount(framer.stats()), 1u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

INSTANTIATE_TEST_SUITE_P(StreamFramerVectors, StreamFramerTruncated,
                         ::testing::Values(TruncatedCase{"Base", kBaseBothMinus6, 9},
                                           TruncatedCase{"Telemetry", kTelemetry, 20},
                                           TruncatedCase{"TelemetryFoot", kTelemetryFoot, 40},
                                           TruncatedCase{"ServoRequest", kServoRotate, 8},
                                           TruncatedCase{"ServoResponse", kServoReadAngleReply, 6},
                                           TruncatedCase{"SyncWrite", kSyncWrite, 15}),
                         [](const ::testing::TestParamInfo<TruncatedCase>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace serial_robot_driver::protocol
