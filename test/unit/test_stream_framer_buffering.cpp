// StreamFramer's buffer: incomplete frames kept, reset, empty feeds, stale candidates.
#include <gtest/gtest.h>

#include "support/framer_configs.h"
#include "support/stream_framer_recording.h"

namespace serial_robot_driver::protocol {
namespace {

using namespace stream_framer_test;  // NOLINT: the shared fixture

// --- reset and accounting ----------------------------------------------------------------------

TEST(StreamFramerState, IncompleteFrameIsKeptUntilTheRestArrives) {
  RecordingFramer framer(allFamilies());
  framer.feed(Bytes(kTelemetry.begin(), kTelemetry.begin() + 10));
  EXPECT_TRUE(framer.frames().empty());
  EXPECT_EQ(framer.framer().buffered(), 10u);
  framer.feed(Bytes(kTelemetry.begin() + 10, kTelemetry.end()));
  ASSERT_EQ(framer.frames().size(), 1u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST(StreamFramerState, ResetDropsThePartialFrame) {
  RecordingFramer framer(allFamilies());
  framer.feed(Bytes(kTelemetry.begin(), kTelemetry.begin() + 10));
  framer.framer().reset();
  EXPECT_EQ(framer.framer().buffered(), 0u);
  EXPECT_EQ(framer.stats().bytes_skipped, 10u);
  // The rest of the old frame is now garbage; a new frame afterwards is found.
  framer.feed(Bytes(kTelemetry.begin() + 10, kTelemetry.end()));
  EXPECT_TRUE(framer.frames().empty());
  EXPECT_EQ(framer.stats().bytes_skipped, kTelemetry.size());
  framer.feed(kServoPing);
  ASSERT_EQ(framer.frames().size(), 1u);
  EXPECT_EQ(framer.frames()[0], (Frame{devices::servo_bus::kRequestFrames, kServoPing}));
  // Statistics survive a reset: they describe the port, not the buffer.
  EXPECT_EQ(framer.stats().bytes_in, kTelemetry.size() + kServoPing.size());
  EXPECT_EQ(frameCount(framer.stats(), devices::servo_bus::kRequestFrames), 1u);
  expectBytesAccountedFor(framer, 0);
}

TEST(StreamFramerState, EmptyFeedChangesNothing) {
  RecordingFramer framer(allFamilies());
  framer.feed(Bytes{});
  framer.feed(Bytes(kBaseReset.begin(), kBaseReset.begin() + 3));
  framer.framer().feed(nullptr, 0);
  EXPECT_EQ(framer.framer().buffered(), 3u);
  EXPECT_EQ(framer.stats().bytes_in, 3u);
  EXPECT_TRUE(framer.frames().empty());
}

// --- a stale incomplete candidate ----------------------------------------------------------------

TEST(StreamFramerStale, AStrayHeaderWithALongLenStopsHoldingBackTheAnswerBehindIt) {
  // 05 1C 01 21: a PING answer header claiming N = 33, so 38 bytes; only the real answer follows.
  Bytes stream = {0x05, 0x1C, 0x01, 0x21};
  stream.insert(stream.end(), golden::servo::kPing3Reply.begin(), golden::servo::kPing3Reply.end());
  RecordingFramer framer(test_support::driverFramer({"servo_bus"}));
  framer.feed(stream);
  EXPECT_TRUE(framer.frames().empty());
  EXPECT_EQ(framer.framer().buffered(), stream.size());

  while (framer.framer().dropStaleCandidate()) {
  }
  ASSERT_EQ(framer.frames().size(), 1u);
  EXPECT_EQ(framer.frames()[0],
            (Frame{devices::servo_bus::kResponseFrames, golden::servo::kPing3Reply}));
  EXPECT_EQ(framer.framer().buffered(), 0u);
  EXPECT_EQ(framer.stats().stale_candidates, 1u);
  EXPECT_EQ(framer.stats().bytes_skipped, 4u);
  expectBytesAccountedFor(framer, 0);
}

TEST(StreamFramerStale, NothingBufferedNothingDropped) {
  RecordingFramer framer(allFamilies());
  EXPECT_FALSE(framer.framer().dropStaleCandidate());
  EXPECT_EQ(framer.stats().stale_candidates, 0u);
}

}  // namespace
}  // namespace serial_robot_driver::protocol
