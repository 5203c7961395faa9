// A kind of frame a stream framer can find on a port. Each codec defines its own families (for
// example base::kFrames in base_codec.h); the framer knows none of them by name, so a new device
// brings its frames by defining a family next to its codec, without editing the framer.
#pragma once

#include <cstddef>
#include <cstdint>

#include "serial_robot_driver/protocol/decode_result.h"

namespace serial_robot_driver::protocol {

/// The codec's probe: is there a complete, verified frame of the family at `data`? `expected` is
/// the per-family argument the framer was configured with (the telemetry's servo count; 0 else).
using ProbeFunction = Probe (*)(const uint8_t* data, std::size_t available, std::size_t expected);
/// The codec's decoder over a frame its probe accepted: true when it decodes it (to a value that
/// agrees with the frame's size). The fuzzers and tests check that probe and decoder agree.
using DecodesFunction = bool (*)(const uint8_t* frame, std::size_t size, std::size_t expected);

struct FrameFamily {
  /// In statistics and logs ("base", "telemetry"); unique among the registered families.
  const char* name;
  /// Every frame of the family starts with this byte.
  uint8_t header0;
  ProbeFunction probe;
  /// Where families share a first byte (telemetry and servo requests: 0x12), the lower rank is
  /// asked first; a kBadHeader answer passes the candidate on to the next.
  int rank;
  DecodesFunction decodes;
};

/// A family is known by its object (copies compare equal: they share the name's storage).
inline bool operator==(const FrameFamily& a, const FrameFamily& b) { return a.name == b.name; }
inline bool operator!=(const FrameFamily& a, const FrameFamily& b) { return !(a == b); }

}  // namespace serial_robot_driver::protocol
