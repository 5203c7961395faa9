// StreamFramer on streams: back-to-back frames, interleaved families, chunking and look-alikes.
#include <gtest/gtest.h>

#include "support/framer_configs.h"
#include "support/stream_framer_recording.h"

namespace serial_robot_driver::protocol {
namespace {

using namespace stream_framer_test;  // NOLINT: the shared fixture

// --- streams -----------------------------------------------------------------------------------

TEST(StreamFramerStream, BackToBackFramesAllComeOutInOrder) {
  const Bytes stream = concat({kBaseReset, kBaseBoth4, kServoPing, kServoPingReply, kTelemetry,
                               kTelemetry, kSyncWrite, kServoDamping, kBaseLen1});
  RecordingFramer framer(allFamilies());
  framer.feed(stream);
  const std::vector<Frame> expected = {{devices::base::kFrames, kBaseReset},
                                       {devices::base::kFrames, kBaseBoth4},
                                       {devices::servo_bus::kRequestFrames, kServoPing},
                                       {devices::servo_bus::kResponseFrames, kServoPingReply},
                                       {devices::body::kTelemetryFrames, kTelemetry},
                                       {devices::body::kTelemetryFrames, kTelemetry},
                                       {devices::body::kSyncWriteFrames, kSyncWrite},
                                       {devices::servo_bus::kRequestFrames, kServoDamping},
                                       {devices::base::kFrames, kBaseLen1}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(frameCount(framer.stats(), devices::base::kFrames), 3u);
  EXPECT_EQ(frameCount(framer.stats(), devices::body::kTelemetryFrames), 2u);
  EXPECT_EQ(frameCount(framer.stats(), devices::servo_bus::kRequestFrames), 2u);
  EXPECT_EQ(frameCount(framer.stats(), devices::servo_bus::kResponseFrames), 1u);
  EXPECT_EQ(frameCount(framer.stats(), devices::body::kSyncWriteFrames), 1u);
  EXPECT_EQ(framer.stats().bytes_skipped, 0u);
  EXPECT_EQ(errorCount(framer.stats()), 0u);
}

TEST(StreamFramerStream, AllFamiliesInterleavedWithJunkOneByteAtATime) {
  const MixedStream stream = mixedStream();
  RecordingFramer framer(allFamilies());
  framer.feedByteByByte(stream.bytes);
  EXPECT_EQ(framer.frames(), stream.frames);
  EXPECT_EQ(framer.stats().bytes_in, stream.bytes.size());
  EXPECT_EQ(framer.stats().bytes_skipped, stream.junk);
  EXPECT_EQ(errorCount(framer.stats()), 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST(StreamFramerStream, RandomChunkSizesGiveTheSameFrames) {
  const MixedStream stream = mixedStream();
  constexpr int kRepeats = 40;
  Bytes bytes;
  std::vector<Frame> expected;
  for (int i = 0; i < kRepeats; ++i) {
    bytes.insert(bytes.end(), stream.bytes.begin(), stream.bytes.end());
    expected.insert(expected.end(), stream.frames.begin(), stream.frames.end());
  }
  for (std::size_t max_chunk : {2u, 7u, 64u, 300u, 5000u}) {
    SCOPED_TRACE("max chunk " + std::to_string(max_chunk));
    std::mt19937 rng(20240611);
    RecordingFramer framer(allFamilies());
    framer.feedInRandomChunks(bytes, &rng, max_chunk);
    EXPECT_EQ(framer.frames(), expected);
    EXPECT_EQ(framer.stats().bytes_skipped, kRepeats * stream.junk);
    EXPECT_EQ(errorCount(framer.stats()), 0u);
    EXPECT_EQ(frameCount(framer.stats(), devices::body::kTelemetryFrames), 2u * kRepeats);
    EXPECT_EQ(frameCount(framer.stats(), devices::body::kSyncWriteFrames), 1u * kRepeats);
    EXPECT_EQ(framer.framer().buffered(), 0u);
  }
}

TEST(StreamFramerStream, ChunkLargerThanTheBuffer) {
  Bytes bytes;
  std::size_t frames = 0;
  while (bytes.size() < 3 * StreamFramer::kBufferSize) {
    bytes = concat({bytes, kTelemetry, kBaseBatteryReply, kServoReadAngleReply});
    frames += 3;
  }
  // End on half a frame so the tail must be buffered from a chunk bigger than the buffer.
  bytes.insert(bytes.end(), kTelemetry.begin(), kTelemetry.begin() + 10);
  RecordingFramer framer(allFamilies());
  framer.feed(bytes);
  EXPECT_EQ(framer.frames().size(), frames);
  EXPECT_EQ(framer.framer().buffered(), 10u);
  framer.feed(Bytes(kTelemetry.begin() + 10, kTelemetry.end()));
  ASSERT_EQ(framer.frames().size(), frames + 1);
  EXPECT_EQ(framer.frames().back(), (Frame{devices::body::kTelemetryFrames, kTelemetry}));
  EXPECT_EQ(framer.stats().bytes_skipped, 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST(StreamFramerStream, JunkWithLoneHeaderBytesIsSkipped) {
  // Each byte below starts some family but is not followed by the rest of its header.
  const Bytes junk = {0x55, 0x55, 0x12, 0x12, 0x05, 0xFF, 0xFE, 0x12, 0x00, 0xFF, 0xFF, 0x00};
  RecordingFramer framer(allFamilies());
  framer.feed(concat({junk, kServoPingReply, junk, kBaseReset, junk}));
  const std::vector<Frame> expected = {{devices::servo_bus::kResponseFrames, kServoPingReply},
                                       {devices::base::kFrames, kBaseReset}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().bytes_skipped, 3 * junk.size());
  EXPECT_EQ(errorCount(framer.stats()), 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST(StreamFramerStream, DynamixelFrameThatIsNotASyncWriteIsSkipped) {
  FramerConfig config = test_support::simulatorFramer();
  RecordingFramer framer(config);
  framer.feed(concat({kDynamixelPing, kSyncWrite}));
  const std::vector<Frame> expected = {{devices::body::kSyncWriteFrames, kSyncWrite}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().bytes_skipped, kDynamixelPing.size());
  EXPECT_EQ(errorCount(framer.stats()), 0u);
}

TEST(StreamFramerStream, TelemetryAndServoRequestShareTheirFirstByte) {
  FramerConfig requests_only;
  requests_only.accept(devices::servo_bus::kRequestFrames);
  RecordingFramer framer(requests_only);
  framer.feed(concat({kTelemetry, kServoPing, kTelemetryFoot, kServoRotate}));
  const std::vector<Frame> expected = {{devices::servo_bus::kRequestFrames, kServoPing},
                                       {devices::servo_bus::kRequestFrames, kServoRotate}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().bytes_skipped, kTelemetry.size() + kTelemetryFoot.size());

  RecordingFramer telemetry_only(test_support::driverFramer({"body"}, kServoCount));
  telemetry_only.feed(concat({kServoPing, kTelemetry, kServoRotate, kTelemetryFoot}));
  const std::vector<Frame> expected_telemetry = {{devices::body::kTelemetryFrames, kTelemetry},
                                                 {devices::body::kTelemetryFrames, kTelemetryFoot}};
  EXPECT_EQ(telemetry_only.frames(), expected_telemetry);
  EXPECT_EQ(telemetry_only.stats().bytes_skipped, kServoPing.size() + kServoRotate.size());
}

TEST(StreamFramerStream, TelemetryLengthFollowsTheConfiguredServoCount) {
  // LEN 32 is 24 + 4*2; with 3 servos only 36 and 52 are legal.
  RecordingFramer three(test_support::driverFramer({"body"}, 3));
  three.feed(kTelemetry);
  EXPECT_TRUE(three.frames().empty());
  EXPECT_EQ(three.stats().bad_lengths, 1u);
  EXPECT_EQ(three.stats().bytes_skipped, kTelemetry.size());

  // LEN 48 is 40 + 4*2 (foot block) but also 24 + 4*6: the configuration decides, not the framer.
  RecordingFramer six(test_support::driverFramer({"body"}, 6));
  six.feed(kTelemetryFoot);
  ASSERT_EQ(six.frames().size(), 1u);
  EXPECT_EQ(six.stats().bad_lengths, 0u);
}

TEST(StreamFramerStream, RealFrameHiddenInsideABrokenOneIsFound) {
  // 55 AA 09 announces a 14-byte base frame; the servo reply and base frame after it complete
  // the candidate, whose XOR (0x35 != 0x05) fails. Dropping one byte then finds both frames.
  const Bytes broken_header = {0x55, 0xAA, 0x09};
  RecordingFramer framer(allFamilies());
  framer.feed(concat({broken_header, kServoPingReply, kBaseReset}));
  const std::vector<Frame> expected = {{devices::servo_bus::kResponseFrames, kServoPingReply},
                                       {devices::base::kFrames, kBaseReset}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().checksum_errors, 1u);
  EXPECT_EQ(framer.stats().bytes_skipped, broken_header.size());
}

}  // namespace
}  // namespace serial_robot_driver::protocol
