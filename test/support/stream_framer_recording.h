// What the StreamFramer tests share: the hand-written frames of every family, a framer that records
// what it emits, stats helpers and a mixed stream of all families with junk.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/framer_configs.h"
#include "support/golden_frames.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::protocol::stream_framer_test {

using test_support::Bytes;
using test_support::concat;

// --- hand-written frames (test/support/golden_frames.h) ---------------------------------------
inline const Bytes& kBaseReset = golden::base::kResetSeq2;
inline const Bytes& kBaseBatteryRequest = golden::base::kBatteryRequestSeq1;
inline const Bytes& kBaseClearEncoders = golden::base::kClearEncodersSeq3;
inline const Bytes& kBaseLeft4 = golden::base::kLeft4Seq0;
inline const Bytes& kBaseRight4 = golden::base::kRight4Seq0;
inline const Bytes& kBaseBoth4 = golden::base::kBoth4Seq0;
inline const Bytes& kBaseBothMinus6 = golden::base::kBothMinus6Seq0;
inline const Bytes& kBaseBatteryReply = golden::base::kBattery100ReplySeq7;
inline const Bytes& kBaseErrorStatus = golden::base::kErrorStatusSeq8;
inline const Bytes& kBaseLen1 = golden::base::kBatteryRequestLen1Seq0;
inline const Bytes& kTelemetry = golden::body::kTelemetryTwoServos;
inline const Bytes& kTelemetryFoot = golden::body::kTelemetryTwoServosFoot;
inline const Bytes& kSyncWrite = golden::body::kSyncWrite2And3;
inline const Bytes& kSyncWriteEmpty = golden::body::kSyncWriteEmpty;
inline const Bytes& kDynamixelPing = golden::body::kDynamixelPing1;
inline const Bytes& kServoPing = golden::servo::kPing3;
inline const Bytes& kServoRotate = golden::servo::kRotate2To90In500;
inline const Bytes& kServoReadAngle = golden::servo::kReadAngle0;
inline const Bytes& kServoSpinCcw = golden::servo::kSpin0CcwContinuous;
inline const Bytes& kServoSpinStop = golden::servo::kSpin0Stop;
inline const Bytes& kServoSpinTurns = golden::servo::kSpin0Cw5Turns;
inline const Bytes& kServoSpinMs = golden::servo::kSpin0Cw1000Ms;
inline const Bytes& kServoDamping = golden::servo::kDamping0At500;
inline const Bytes& kServoPingReply = golden::servo::kPing3Reply;
inline const Bytes& kServoReadAngleReply = golden::servo::kReadAngle0Reply902;
inline const Bytes& kServoEmptyReply = golden::servo::kEmptyPingReply;

constexpr std::size_t kServoCount = 2;

inline FramerConfig allFamilies() { return test_support::everyFamily(kServoCount); }

struct Frame {
  FrameFamily family;
  Bytes bytes;
  bool operator==(const Frame& other) const {
    return family == other.family && bytes == other.bytes;
  }
};

inline std::ostream& operator<<(std::ostream& os, const Frame& frame) {
  os << frame.family.name << " [" << frame.bytes.size() << " bytes]";
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

inline uint64_t frameCount(const FramerStats& stats, FrameFamily family) {
  return stats.framesOf(family);
}

inline uint64_t totalFrames(const FramerStats& stats) {
  uint64_t total = 0;
  for (std::size_t i = 0; i < stats.family_count; ++i) total += stats.by_family[i].frames;
  return total;
}

inline uint64_t errorCount(const FramerStats& stats) {
  return stats.checksum_errors + stats.bad_tails + stats.bad_lengths + stats.unknown_commands;
}

// Every input byte is either in an emitted frame, skipped, or still buffered.
inline void expectBytesAccountedFor(const RecordingFramer& framer, std::size_t buffered) {
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

inline MixedStream mixedStream() {
  // Junk without any header byte, so the skip count is exact.
  const Bytes junk = {0x00, 0x01, 0xAA, 0x34, 0x4C, 0x1C, 0xFD, 0x7E};
  const std::vector<Frame> frames = {
      {devices::body::kTelemetryFrames, kTelemetry},
      {devices::base::kFrames, kBaseBatteryReply},
      {devices::servo_bus::kResponseFrames, kServoPingReply},
      {devices::servo_bus::kRequestFrames, kServoRotate},
      {devices::body::kSyncWriteFrames, kSyncWrite},
      {devices::body::kTelemetryFrames, kTelemetryFoot},
      {devices::base::kFrames, kBaseErrorStatus},
      {devices::servo_bus::kRequestFrames, kServoReadAngle},
      {devices::servo_bus::kResponseFrames, kServoReadAngleReply},
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

}  // namespace serial_robot_driver::protocol::stream_framer_test
