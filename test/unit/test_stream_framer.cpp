// Stream framer: resynchronisation, chunking and statistics. Every frame below is written out by
// hand from docs/protocols.md (golden vectors) or derived from one with a hand-computed checksum.
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "serial_robot_driver/protocol/base_codec.h"
#include "serial_robot_driver/protocol/body_codec.h"
#include "serial_robot_driver/protocol/servo_bus_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/golden_frames.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::protocol {
namespace {

using test_support::Bytes;
using test_support::concat;

// --- hand-written frames (test/support/golden_frames.h) ---------------------------------------
const Bytes& kBaseReset = golden::base::kResetSeq2;
const Bytes& kBaseBatteryRequest = golden::base::kBatteryRequestSeq1;
const Bytes& kBaseClearEncoders = golden::base::kClearEncodersSeq3;
const Bytes& kBaseLeft4 = golden::base::kLeft4Seq0;
const Bytes& kBaseRight4 = golden::base::kRight4Seq0;
const Bytes& kBaseBoth4 = golden::base::kBoth4Seq0;
const Bytes& kBaseBothMinus6 = golden::base::kBothMinus6Seq0;
const Bytes& kBaseBatteryReply = golden::base::kBattery100ReplySeq7;
const Bytes& kBaseErrorStatus = golden::base::kErrorStatusSeq8;
const Bytes& kBaseLen1 = golden::base::kBatteryRequestLen1Seq0;
const Bytes& kTelemetry = golden::body::kTelemetryTwoServos;
const Bytes& kTelemetryFoot = golden::body::kTelemetryTwoServosFoot;
const Bytes& kSyncWrite = golden::body::kSyncWrite2And3;
const Bytes& kSyncWriteEmpty = golden::body::kSyncWriteEmpty;
const Bytes& kDynamixelPing = golden::body::kDynamixelPing1;
const Bytes& kServoPing = golden::servo::kPing3;
const Bytes& kServoRotate = golden::servo::kRotate2To90In500;
const Bytes& kServoReadAngle = golden::servo::kReadAngle0;
const Bytes& kServoSpinCcw = golden::servo::kSpin0CcwContinuous;
const Bytes& kServoSpinStop = golden::servo::kSpin0Stop;
const Bytes& kServoSpinTurns = golden::servo::kSpin0Cw5Turns;
const Bytes& kServoSpinMs = golden::servo::kSpin0Cw1000Ms;
const Bytes& kServoDamping = golden::servo::kDamping0At500;
const Bytes& kServoPingReply = golden::servo::kPing3Reply;
const Bytes& kServoReadAngleReply = golden::servo::kReadAngle0Reply902;
const Bytes& kServoEmptyReply = golden::servo::kEmptyPingReply;

constexpr std::size_t kServoCount = 2;

FramerConfig allFamilies() {
  FramerConfig config;
  config.base = true;
  config.telemetry = true;
  config.servo_response = true;
  config.servo_request = true;
  config.sync_write = true;
  config.telemetry_servo_count = kServoCount;
  return config;
}

struct Frame {
  FrameFamily family;
  Bytes bytes;
  bool operator==(const Frame& other) const {
    return family == other.family && bytes == other.bytes;
  }
};

std::ostream& operator<<(std::ostream& os, const Frame& frame) {
  os << toString(frame.family) << " [" << frame.bytes.size() << " bytes]";
  return os;
}

// A framer that records every frame it emits.
class RecordingFramer {
 public:
  explicit RecordingFramer(const FramerConfig& config)
      : framer_(config, [this](FrameFamily family, const uint8_t* data, std::size_t size) {
          frames_.push_back({family, Bytes(data, data + size)});
        }) {}
  RecordingFramer(const RecordingFramer&) = delete;
  RecordingFramer& operator=(const RecordingFramer&) = delete;

  void feed(const Bytes& bytes) { framer_.feed(bytes.data(), bytes.size()); }
  void feedByteByByte(const Bytes& bytes) {
    for (uint8_t byte : bytes) framer_.feed(&byte, 1);
  }
  void feedInRandomChunks(const Bytes& bytes, std::mt19937* rng, std::size_t max_chunk) {
    std::uniform_int_distribution<std::size_t> chunk_size(1, max_chunk);
    std::size_t pos = 0;
    while (pos < bytes.size()) {
      const std::size_t n = std::min(chunk_size(*rng), bytes.size() - pos);
      framer_.feed(bytes.data() + pos, n);
      pos += n;
      ASSERT_LT(framer_.buffered(), 2 * StreamFramer::kLongestFrame);
    }
  }

  StreamFramer& framer() { return framer_; }
  const FramerStats& stats() const { return framer_.stats(); }
  const std::vector<Frame>& frames() const { return frames_; }

 private:
  std::vector<Frame> frames_;
  StreamFramer framer_;
};

uint64_t frameCount(const FramerStats& stats, FrameFamily family) {
  return stats.frames[static_cast<std::size_t>(family)];
}

uint64_t totalFrames(const FramerStats& stats) {
  return std::accumulate(stats.frames.begin(), stats.frames.end(), uint64_t{0});
}

uint64_t errorCount(const FramerStats& stats) {
  return stats.checksum_errors + stats.bad_tails + stats.bad_lengths + stats.unknown_commands;
}

// Every input byte is either in an emitted frame, skipped, or still buffered.
void expectBytesAccountedFor(const RecordingFramer& framer, std::size_t buffered) {
  uint64_t frame_bytes = 0;
  for (const Frame& frame : framer.frames()) frame_bytes += frame.bytes.size();
  EXPECT_EQ(framer.stats().bytes_in, frame_bytes + framer.stats().bytes_skipped + buffered);
}

// The mixed stream used by several tests, with what the framer must find in it.
struct MixedStream {
  Bytes bytes;
  std::vector<Frame> frames;
  std::size_t junk = 0;
};

MixedStream mixedStream() {
  // Junk without any header byte, so the skip count is exact.
  const Bytes junk = {0x00, 0x01, 0xAA, 0x34, 0x4C, 0x1C, 0xFD, 0x7E};
  const std::vector<Frame> frames = {
      {protocol::body::kTelemetryFrames, kTelemetry},
      {protocol::base::kFrames, kBaseBatteryReply},
      {protocol::servo::kResponseFrames, kServoPingReply},
      {protocol::servo::kRequestFrames, kServoRotate},
      {protocol::body::kSyncWriteFrames, kSyncWrite},
      {protocol::body::kTelemetryFrames, kTelemetryFoot},
      {protocol::base::kFrames, kBaseErrorStatus},
      {protocol::servo::kRequestFrames, kServoReadAngle},
      {protocol::servo::kResponseFrames, kServoReadAngleReply},
  };
  MixedStream stream;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i % 3 == 1) {
      stream.bytes.insert(stream.bytes.end(), junk.begin(), junk.end());
      stream.junk += junk.size();
    }
    stream.bytes.insert(stream.bytes.end(), frames[i].bytes.begin(), frames[i].bytes.end());
    stream.frames.push_back(frames[i]);
  }
  return stream;
}

// --- small pieces ------------------------------------------------------------------------------

TEST(StreamFramerConfig, ToStringNamesEveryFamily) {
  EXPECT_STREQ(toString(protocol::base::kFrames), "base");
  EXPECT_STREQ(toString(protocol::body::kTelemetryFrames), "telemetry");
  EXPECT_STREQ(toString(protocol::servo::kResponseFrames), "servo_response");
  EXPECT_STREQ(toString(protocol::servo::kRequestFrames), "servo_request");
  EXPECT_STREQ(toString(protocol::body::kSyncWriteFrames), "sync_write");
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
    case protocol::base::kFrames:
      config.base = false;
      break;
    case protocol::body::kTelemetryFrames:
      config.telemetry = false;
      break;
    case protocol::servo::kResponseFrames:
      config.servo_response = false;
      break;
    case protocol::servo::kRequestFrames:
      config.servo_request = false;
      break;
    case protocol::body::kSyncWriteFrames:
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
    ::testing::Values(GoldenCase{"BaseReset", kBaseReset, protocol::base::kFrames},
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
                      GoldenCase{"ServoReadAngleReply", kServoReadAngleReply,
                                 protocol::servo::kResponseFrames},
                      GoldenCase{"ServoEmptyReply", kServoEmptyReply, protocol::servo::kResponseFrames}),
    [](const ::testing::TestParamInfo<GoldenCase>& info) { return info.param.name; });

// --- streams -----------------------------------------------------------------------------------

TEST(StreamFramerStream, BackToBackFramesAllComeOutInOrder) {
  const Bytes stream = concat({kBaseReset, kBaseBoth4, kServoPing, kServoPingReply, kTelemetry,
                               kTelemetry, kSyncWrite, kServoDamping, kBaseLen1});
  RecordingFramer framer(allFamilies());
  framer.feed(stream);
  const std::vector<Frame> expected = {
      {protocol::base::kFrames, kBaseReset},         {protocol::base::kFrames, kBaseBoth4},
      {protocol::servo::kRequestFrames, kServoPing}, {protocol::servo::kResponseFrames, kServoPingReply},
      {protocol::body::kTelemetryFrames, kTelemetry},    {protocol::body::kTelemetryFrames, kTelemetry},
      {protocol::body::kSyncWriteFrames, kSyncWrite},    {protocol::servo::kRequestFrames, kServoDamping},
      {protocol::base::kFrames, kBaseLen1}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(frameCount(framer.stats(), protocol::base::kFrames), 3u);
  EXPECT_EQ(frameCount(framer.stats(), protocol::body::kTelemetryFrames), 2u);
  EXPECT_EQ(frameCount(framer.stats(), protocol::servo::kRequestFrames), 2u);
  EXPECT_EQ(frameCount(framer.stats(), protocol::servo::kResponseFrames), 1u);
  EXPECT_EQ(frameCount(framer.stats(), protocol::body::kSyncWriteFrames), 1u);
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
    EXPECT_EQ(frameCount(framer.stats(), protocol::body::kTelemetryFrames), 2u * kRepeats);
    EXPECT_EQ(frameCount(framer.stats(), protocol::body::kSyncWriteFrames), 1u * kRepeats);
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
  EXPECT_EQ(framer.frames().back(), (Frame{protocol::body::kTelemetryFrames, kTelemetry}));
  EXPECT_EQ(framer.stats().bytes_skipped, 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST(StreamFramerStream, JunkWithLoneHeaderBytesIsSkipped) {
  // Each byte below starts some family but is not followed by the rest of its header.
  const Bytes junk = {0x55, 0x55, 0x12, 0x12, 0x05, 0xFF, 0xFE, 0x12, 0x00, 0xFF, 0xFF, 0x00};
  RecordingFramer framer(allFamilies());
  framer.feed(concat({junk, kServoPingReply, junk, kBaseReset, junk}));
  const std::vector<Frame> expected = {{protocol::servo::kResponseFrames, kServoPingReply},
                                       {protocol::base::kFrames, kBaseReset}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().bytes_skipped, 3 * junk.size());
  EXPECT_EQ(errorCount(framer.stats()), 0u);
  EXPECT_EQ(framer.framer().buffered(), 0u);
}

TEST(StreamFramerStream, DynamixelFrameThatIsNotASyncWriteIsSkipped) {
  FramerConfig config = FramerConfig::forSimulator();
  RecordingFramer framer(config);
  framer.feed(concat({kDynamixelPing, kSyncWrite}));
  const std::vector<Frame> expected = {{protocol::body::kSyncWriteFrames, kSyncWrite}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().bytes_skipped, kDynamixelPing.size());
  EXPECT_EQ(errorCount(framer.stats()), 0u);
}

TEST(StreamFramerStream, TelemetryAndServoRequestShareTheirFirstByte) {
  FramerConfig requests_only;
  requests_only.servo_request = true;
  RecordingFramer framer(requests_only);
  framer.feed(concat({kTelemetry, kServoPing, kTelemetryFoot, kServoRotate}));
  const std::vector<Frame> expected = {{protocol::servo::kRequestFrames, kServoPing},
                                       {protocol::servo::kRequestFrames, kServoRotate}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().bytes_skipped, kTelemetry.size() + kTelemetryFoot.size());

  RecordingFramer telemetry_only(FramerConfig::forDriver(false, true, false, kServoCount));
  telemetry_only.feed(concat({kServoPing, kTelemetry, kServoRotate, kTelemetryFoot}));
  const std::vector<Frame> expected_telemetry = {{protocol::body::kTelemetryFrames, kTelemetry},
                                                 {protocol::body::kTelemetryFrames, kTelemetryFoot}};
  EXPECT_EQ(telemetry_only.frames(), expected_telemetry);
  EXPECT_EQ(telemetry_only.stats().bytes_skipped, kServoPing.size() + kServoRotate.size());
}

TEST(StreamFramerStream, TelemetryLengthFollowsTheConfiguredServoCount) {
  // LEN 32 is 24 + 4*2; with 3 servos only 36 and 52 are legal.
  RecordingFramer three(FramerConfig::forDriver(false, true, false, 3));
  three.feed(kTelemetry);
  EXPECT_TRUE(three.frames().empty());
  EXPECT_EQ(three.stats().bad_lengths, 1u);
  EXPECT_EQ(three.stats().bytes_skipped, kTelemetry.size());

  // LEN 48 is 40 + 4*2 (foot block) but also 24 + 4*6: the configuration decides, not the framer.
  RecordingFramer six(FramerConfig::forDriver(false, true, false, 6));
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
  const std::vector<Frame> expected = {{protocol::servo::kResponseFrames, kServoPingReply},
                                       {protocol::base::kFrames, kBaseReset}};
  EXPECT_EQ(framer.frames(), expected);
  EXPECT_EQ(framer.stats().checksum_errors, 1u);
  EXPECT_EQ(framer.stats().bytes_skipped, broken_header.size());
}

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
  for (const Frame& good :
       {Frame{protocol::servo::kResponseFrames, kServoPingReply},
        Frame{protocol::base::kFrames, kBaseBatteryReply}, Frame{protocol::body::kSyncWriteFrames, kSyncWrite}}) {
    SCOPED_TRACE(toString(good.family));
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
  EXPECT_EQ(framer.frames()[0], (Frame{protocol::servo::kResponseFrames, kServoPingReply}));
  EXPECT_EQ(framer.frames()[5], (Frame{protocol::base::kFrames, kBaseBatteryReply}));
  EXPECT_EQ(framer.frames()[6], (Frame{protocol::body::kTelemetryFrames, kTelemetry}));
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
  EXPECT_EQ(framer.frames()[0], (Frame{protocol::servo::kRequestFrames, kServoPing}));
  // Statistics survive a reset: they describe the port, not the buffer.
  EXPECT_EQ(framer.stats().bytes_in, kTelemetry.size() + kServoPing.size());
  EXPECT_EQ(frameCount(framer.stats(), protocol::servo::kRequestFrames), 1u);
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

// --- random junk
// -----------------------------------------------------------------------------------

// Checks a frame the framer emitted against the family's own decoder.
void expectDecoderAccepts(const Frame& frame) {
  const uint8_t* data = frame.bytes.data();
  const std::size_t size = frame.bytes.size();
  switch (frame.family) {
    case protocol::base::kFrames: {
      const auto decoded = base::decodeFrame(data, size);
      EXPECT_TRUE(decoded.ok()) << toString(decoded.error());
      break;
    }
    case protocol::body::kTelemetryFrames: {
      const auto decoded = body::decodeTelemetry(data, size, kServoCount);
      EXPECT_TRUE(decoded.ok()) << toString(decoded.error());
      break;
    }
    case protocol::servo::kResponseFrames: {
      const auto decoded = servo::decodeResponse(data, size);
      EXPECT_TRUE(decoded.ok()) << toString(decoded.error());
      break;
    }
    case protocol::servo::kRequestFrames: {
      const auto decoded = servo::decodeRequest(data, size);
      EXPECT_TRUE(decoded.ok()) << toString(decoded.error());
      break;
    }
    case protocol::body::kSyncWriteFrames: {
      const auto decoded = body::decodeSyncWrite(data, size);
      EXPECT_TRUE(decoded.ok()) << toString(decoded.error());
      break;
    }
  }
}

TEST(StreamFramerJunk, UniformRandomBytesNeverYieldABadFrame) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> byte(0, 255);
  Bytes junk(1 << 20);
  for (uint8_t& b : junk) b = static_cast<uint8_t>(byte(rng));
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(junk, &rng, 1000);
  for (const Frame& frame : framer.frames()) expectDecoderAccepts(frame);
  expectBytesAccountedFor(framer, framer.framer().buffered());
  EXPECT_GT(framer.stats().bytes_skipped, junk.size() / 2);
}

TEST(StreamFramerJunk, HeaderRichRandomBytesNeverYieldABadFrame) {
  // Bytes drawn mostly from the headers and small lengths, so that candidates are everywhere and
  // some pass their 8-bit check by chance: those must still satisfy the decoders.
  const Bytes alphabet = {0x55, 0xAA, 0x12, 0x34, 0x4C, 0x05, 0x1C, 0xFF, 0xFD, 0x00, 0xFE,
                          0x83, 0x01, 0x02, 0x03, 0x07, 0x0A, 0x0D, 0x20, 0x30, 0x1F, 0x2F};
  std::mt19937 rng(777);
  std::uniform_int_distribution<std::size_t> pick(0, alphabet.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  Bytes junk(1 << 19);
  for (uint8_t& b : junk) {
    b = (rng() % 4 == 0) ? static_cast<uint8_t>(byte(rng)) : alphabet[pick(rng)];
  }
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(junk, &rng, 64);
  for (const Frame& frame : framer.frames()) expectDecoderAccepts(frame);
  expectBytesAccountedFor(framer, framer.framer().buffered());
  EXPECT_GT(totalFrames(framer.stats()), 0u);  // the test exercised the emit path
  EXPECT_GT(framer.stats().checksum_errors, 0u);
  EXPECT_GT(framer.stats().bad_lengths, 0u);
}

TEST(StreamFramerJunk, GoodFramesSurviveBeingSurroundedByJunk) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255);
  const MixedStream stream = mixedStream();
  Bytes bytes;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 300; ++j) bytes.push_back(static_cast<uint8_t>(byte(rng)));
    bytes.insert(bytes.end(), stream.bytes.begin(), stream.bytes.end());
  }
  RecordingFramer framer(allFamilies());
  framer.feedInRandomChunks(bytes, &rng, 100);
  // Junk may hide a frame only by forming a longer candidate that swallows it and then passes its
  // check, which random bytes practically never do: every good frame must come through.
  std::size_t found = 0;
  for (const Frame& frame : framer.frames()) {
    expectDecoderAccepts(frame);
    if (found < 50 * stream.frames.size() && frame == stream.frames[found % stream.frames.size()]) {
      ++found;
    }
  }
  EXPECT_EQ(found, 50 * stream.frames.size());
}

}  // namespace
}  // namespace serial_robot_driver::protocol

// --- a stale incomplete candidate ----------------------------------------------------------------

namespace serial_robot_driver::protocol {
namespace {

TEST(StreamFramerStale, AStrayHeaderWithALongLenStopsHoldingBackTheAnswerBehindIt) {
  // 05 1C 01 21: a PING answer header claiming N = 33, so 38 bytes; only the real answer follows.
  Bytes stream = {0x05, 0x1C, 0x01, 0x21};
  stream.insert(stream.end(), golden::servo::kPing3Reply.begin(), golden::servo::kPing3Reply.end());
  RecordingFramer framer(FramerConfig::forDriver(false, false, true, 0));
  framer.feed(stream);
  EXPECT_TRUE(framer.frames().empty());
  EXPECT_EQ(framer.framer().buffered(), stream.size());

  while (framer.framer().dropStaleCandidate()) {
  }
  ASSERT_EQ(framer.frames().size(), 1u);
  EXPECT_EQ(framer.frames()[0], (Frame{protocol::servo::kResponseFrames, golden::servo::kPing3Reply}));
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
