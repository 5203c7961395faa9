// libFuzzer target: the stream framer over arbitrary bytes, with every family it can be configured
// for, fed in arbitrary chunks; every frame it emits goes to that family's decoder.
//
// Input layout (so that seeds are plain frames behind a 3-byte prefix):
//   byte 0  families: bit 0 base, 1 telemetry, 2 servo response, 3 servo request, 4 sync write,
//           bit 7: reset() half way through the stream
//   byte 1  configured telemetry servo count (used modulo 64, so also beyond the legal 57)
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

#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"

namespace {

using serial_robot_driver::protocol::DecodeError;
using serial_robot_driver::protocol::FrameFamily;
using serial_robot_driver::protocol::FramerConfig;
using serial_robot_driver::protocol::StreamFramer;
namespace base = serial_robot_driver::protocol::base;
namespace body = serial_robot_driver::protocol::body;
namespace servo = serial_robot_driver::protocol::servo;

void check(bool condition) {
  if (!condition) std::abort();
}

// The families input byte 0 selects, bit by bit.
const FrameFamily* const kFamilies[] = {&base::kFrames, &body::kTelemetryFrames,
                                        &servo::kResponseFrames, &servo::kRequestFrames,
                                        &body::kSyncWriteFrames};

// A verified frame may still carry content its decoder refuses (a Dynamixel sync write to another
// address), but never a framing error.
template <typename T>
void checkFramingAgrees(const serial_robot_driver::protocol::Decoded<T>& decoded) {
  check(decoded.ok() || decoded.error() == DecodeError::kUnexpectedContent);
}

void decodeFrame(const FramerConfig& config, const FrameFamily& family, const uint8_t* frame,
                 std::size_t size) {
  check(config.accepts(family));
  check(size > 0 && size <= StreamFramer::kLongestFrame);
  // An exact-size heap copy, so that a decoder reading past the frame trips ASan.
  std::unique_ptr<uint8_t[]> copy(new uint8_t[size]);
  std::memcpy(copy.get(), frame, size);
  const uint8_t* data = copy.get();
  if (family == base::kFrames) {
    const auto decoded = base::decodeFrame(data, size);
    check(decoded.ok());
    (void)base::interpretReply(*decoded);
    (void)base::interpretWheelSpeed(*decoded);
  } else if (family == body::kTelemetryFrames) {
    const std::size_t servo_count = config.expectedOf(body::kTelemetryFrames);
    const auto decoded = body::decodeTelemetry(data, size, servo_count);
    check(decoded.ok());
    check(decoded->servo_count == servo_count);
  } else if (family == servo::kResponseFrames) {
    const auto decoded = servo::decodeResponse(data, size);
    check(decoded.ok());
    check(decoded->content_size + servo::kOverhead == size);
  } else if (family == servo::kRequestFrames) {
    const auto decoded = servo::decodeRequest(data, size);
    check(decoded.ok());
    check(decoded->content_size + servo::kOverhead == size);
  } else if (family == body::kSyncWriteFrames) {
    checkFramingAgrees(body::decodeSyncWrite(data, size));
  } else {
    check(false);  // a family nobody configured
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* input, std::size_t input_size) {
  constexpr std::size_t kPrefix = 3;
  if (input_size < kPrefix) return 0;
  FramerConfig config;
  for (std::size_t bit = 0; bit < sizeof(kFamilies) / sizeof(kFamilies[0]); ++bit) {
    // The telemetry's argument: its servo count.
    const std::size_t expected = kFamilies[bit] == &body::kTelemetryFrames ? input[1] % 64 : 0;
    if (input[0] & (1u << bit)) config.accept(*kFamilies[bit], expected);
  }
  const bool reset_half_way = (input[0] & 0x80) != 0;
  const std::size_t max_chunk = input[2];

  const uint8_t* stream = input + kPrefix;
  const std::size_t stream_size = input_size - kPrefix;

  uint64_t frame_bytes = 0;
  StreamFramer framer(config, [&](const FrameFamily& family, const uint8_t* data, std::size_t size) {
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
