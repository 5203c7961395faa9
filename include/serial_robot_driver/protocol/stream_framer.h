// One stream framer per serial port: it takes byte chunks of any size, finds complete frames of the
// families it is configured for and hands each one to a callback together with its family.
// The framer knows no layout and no family by name: it is configured with the families to accept
// (protocol/frame_family.h: first header byte and the codec's probe), and each probe says "need
// more", "invalid (why)" or "frame of N bytes" (verified: LEN, checksum, tail). Several devices can
// therefore share one port: their inbound headers differ (docs/protocols.md, table at the top).
//
// Design (after kobuki's packet finder and novatel's multi-family extractor):
//  - fixed-size buffer, no heap allocation after construction;
//  - on garbage, a bad checksum/tail or an impossible LEN, drop ONE byte and rescan, so a real
//    frame hidden inside a broken one is still found;
//  - a frame whose length is plausible but which is not complete yet is kept until more bytes come.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>

#include "serial_robot_driver/protocol/decode_result.h"
#include "serial_robot_driver/protocol/frame_family.h"

namespace serial_robot_driver::protocol {

/// The most families one framer accepts (the driver's ports carry one to three).
constexpr std::size_t kMaxFamiliesPerFramer = 8;

/// What a framer accepts: families and, per family, the argument its probe gets.
struct FramerConfig {
  struct Accepted {
    FrameFamily family;
    std::size_t expected = 0;  ///< passed to the family's probe (the telemetry's servo count)
  };
  std::array<Accepted, kMaxFamiliesPerFramer> families{};
  std::size_t family_count = 0;

  /// Accept frames of `family` as well (again: only `expected` is updated). Throws
  /// std::length_error beyond kMaxFamiliesPerFramer families.
  void accept(const FrameFamily& family, std::size_t expected = 0);
  bool accepts(const FrameFamily& family) const;
  /// The probe argument `family` was accepted with (0 when it is not accepted).
  std::size_t expectedOf(const FrameFamily& family) const;
};

struct FramerStats {
  uint64_t bytes_in = 0;
  uint64_t bytes_skipped = 0;    ///< bytes dropped while resynchronising
  uint64_t checksum_errors = 0;  ///< complete candidates whose XOR/sum/CRC failed
  uint64_t bad_tails = 0;        ///< telemetry with a wrong 1F 2F tail
  uint64_t bad_lengths = 0;      ///< impossible LEN bytes
  uint64_t unknown_commands = 0;  ///< servo-bus headers with a CMD outside 1..16
  uint64_t stale_candidates = 0;  ///< incomplete candidates given up on (dropStaleCandidate)
  /// Verified frames per accepted family, in the order the config names them.
  struct FamilyFrames {
    const char* family = nullptr;  ///< FrameFamily::name
    uint64_t frames = 0;
  };
  std::array<FamilyFrames, kMaxFamiliesPerFramer> by_family{};
  std::size_t family_count = 0;

  /// Verified frames of `family` (0 when it is not accepted).
  uint64_t framesOf(const FrameFamily& family) const;
  /// Adds every counter of `other` (a family it has and this has not is appended).
  void add(const FramerStats& other);
};

class StreamFramer {
 public:
  /// Called for every verified frame. `data` points into the framer's buffer or into the chunk
  /// passed to feed(), and is valid only during the call. The handler must not throw, nor call
  /// feed() or reset() on the same framer.
  using FrameHandler =
      std::function<void(const FrameFamily& family, const uint8_t* data, std::size_t size)>;

  /// Large enough for several of the longest frames (telemetry: 255 bytes).
  static constexpr std::size_t kBufferSize = 4096;
  /// The longest frame of any family (telemetry: LEN is one byte and counts the whole frame).
  static constexpr std::size_t kLongestFrame = 255;

  StreamFramer(const FramerConfig& config, FrameHandler handler);

  /// Feeds bytes as they arrived from the port (any size, also larger than kBufferSize); calls the
  /// handler for each complete frame. Never allocates.
  void feed(const uint8_t* data, std::size_t size);
  /// Drops buffered bytes (after a reconnect the old partial frame is meaningless). They are
  /// counted in bytes_skipped; the other statistics are kept.
  void reset();
  /// Gives up on the incomplete candidate kept for the next feed(): drops its first byte and
  /// rescans the bytes behind it, handing out the frames found there. A stray header with a long
  /// LEN would otherwise hold back the answers behind it until enough bytes arrive. The owner calls
  /// this when no byte has arrived for a while. Returns false when nothing was buffered.
  bool dropStaleCandidate();

  const FramerStats& stats() const { return stats_; }
  const FramerConfig& config() const { return config_; }
  /// Bytes of an incomplete candidate frame kept for the next feed() (always < 2 * kLongestFrame).
  std::size_t buffered() const { return size_; }

 private:
  /// One accepted family; `stats_index` is its slot in stats_.by_family.
  struct Entry {
    FramerConfig::Accepted accepted{};
    std::size_t stats_index = 0;
  };
  void addEntry(const FramerConfig::Accepted& accepted, std::size_t stats_index);
  /// Asks the entries whose first header byte matches, in table order; a kBadHeader from one
  /// (two families share 0x12) passes the candidate to the next. Counts length/checksum/tail
  /// errors.
  Probe examine(const uint8_t* data, std::size_t available, const Entry** found);
  /// Emits the frames found among the bytes at `data`, examining candidates that start before
  /// `start_limit`. Returns how many bytes were consumed: it stops early only at an incomplete
  /// candidate.
  std::size_t scan(const uint8_t* data, std::size_t available, std::size_t start_limit);
  /// Position of the first byte in [from, to) that may start an enabled family, or `to`.
  std::size_t findStart(const uint8_t* data, std::size_t from, std::size_t to) const;

  FramerConfig config_;
  FrameHandler handler_;
  FramerStats stats_;
  std::array<Entry, kMaxFamiliesPerFramer> entries_{};
  std::size_t entry_count_ = 0;
  /// is_start_[b]: b is the first header byte of an enabled family.
  std::array<bool, 256> is_start_{};
  /// first_entry_[b]: index of the first entry whose header starts with b (kNoEntry: none).
  static constexpr uint8_t kNoEntry = 0xFF;
  std::array<uint8_t, 256> first_entry_{};
  /// The only start byte when exactly one is enabled (memchr applies), else -1.
  int single_start_ = -1;
  std::array<uint8_t, kBufferSize> buffer_{};
  std::size_t size_ = 0;
};

}  // namespace serial_robot_driver::protocol
