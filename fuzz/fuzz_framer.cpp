// libFuzzer target: the stream framer over arbitrary bytes, with every frame family of the
// registered devices it can be configured for, fed in arbitrary chunks; every frame it emits goes
// to that family's decoder (FrameFamily::decodes).
//
// Input layout (so that seeds are plain frames behind a 3-byte prefix):
//   byte 0  families: bit i the i-th registered family (registered_families.h: base, telemetry,
//           sync write, servo response, servo request, ...), bit 7: reset() half way through
//   byte 1  every probe's argument, modulo 64 (the telemetry's servo count, so also beyond 57)
//   byte 2  largest chunk size (0: the whole stream in one feed), chunk sizes drawn from it
//   rest    the byte stream
//
// Aborts when: the framer emits a frame of a disabled family, a frame its decoder rejects for a
// framing reason (size, header, length, checksum, tail), loses track of a byte, or lets its buffer
// grow; ASan/UBSan abort on any out-of-bounds access or undefined behaviour.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "registered_families.h"
#include "serial_robot_driver/protocol/stream_framer.h"

namespace {

using serial_robot_driver::protocol::FrameFamily;
using serial_robot_driver::protocol::FramerConfig;
using serial_robot_driver::protocol::StreamFramer;

void check(bool condition) {
  if (!condition) std::abort();
}

void decodeFrame(const FramerConfig& config, const FrameFamily& family, const uint8_t* frame,
                 std::size_t size) {
  check(config.accepts(family));
  check(size > 0 && size <= StreamFramer::kLongestFrame);
  // An exact-size heap copy, so that a decoder reading past the frame trips ASan.
  std::unique_ptr<uint8_t[]> copy(new uint8_t[size]);
  std::memcpy(copy.get(), frame, size);
  // The family's own decoder must take what its probe accepted.
  check(family.decodes(copy.get(), size, config.expectedOf(family)));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* input, std::size_t input_size) {
  constexpr std::size_t kPrefix = 3;
  if (input_size < kPrefix) return 0;
  FramerConfig config;
  const auto& families = fuzz_support::registeredFamilies();
  for (std::size_t bit = 0; bit < families.size() && bit < 7; ++bit) {
    // Every probe gets byte 1 as its argument (the telemetry: its servo count; others ignore it).
    if (input[0] & (1u << bit)) config.accept(families[bit], input[1] % 64);
  }
  const bool reset_half_way = (input[0] & 0x80) != 0;
  const std::size_t max_chunk = input[2];

  const uint8_t* stream = input + kPrefix;
  const std::size_t stream_size = input_size - kPrefix;

  uint64_t frame_bytes = 0;
  StreamFramer framer(config,
                      [&](const FrameFamily& family, const uint8_t* data, std::size_t size) {
                        frame_bytes += size;
                        decodeFrame(config, family, data, size);
                      });

  // Chunk sizes from a small xorshift seeded by the input, so they do not eat stream bytes.
  uint32_t rng = 0x9E3779B9u ^ (static_cast<uint32_t>(input[0]) << 16) ^ input[1];
  std::size_t pos = 0;
  bool was_reset = false;
  uint64_t dropped_by_reset = 0;
  while (pos < stream_size) {
    std::size_t chunk = stream_size - pos;
    if (max_chunk != 0) {
      rng ^= rng << 13;
      rng ^= rng >> 17;
      rng ^= rng << 5;
      chunk = std::min<std::size_t>(chunk, 1 + rng % max_chunk);
    }
    // Exact-size heap copy again: the framer must never read past the chunk it was given.
    std::unique_ptr<uint8_t[]> copy(new uint8_t[chunk]);
    std::memcpy(copy.get(), stream + pos, chunk);
    framer.feed(copy.get(), chunk);
    pos += chunk;
    check(framer.buffered() < 2 * StreamFramer::kLongestFrame);
    if (reset_half_way && !was_reset && pos >= stream_size / 2) {
      dropped_by_reset = framer.buffered();
      framer.reset();
      check(framer.buffered() == 0);
      was_reset = true;
    }
  }

  // Every byte is in a frame, skipped (reset() counts what it drops), or still buffered.
  const auto& stats = framer.stats();
  check(stats.bytes_in == stream_size);
  check(stats.bytes_in == frame_bytes + stats.bytes_skipped + framer.buffered());
  check(stats.bytes_skipped >= dropped_by_reset);
  return 0;
}
