// Explicit byte-order helpers. The three protocols mix big-endian (base speeds, telemetry) and
// little-endian (sync-write, foot block, servo bus) fields, so every multi-byte access names its order.
#pragma once

#include <cstdint>

namespace serial_robot_driver::protocol {

inline uint16_t readBE16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }
inline uint16_t readLE16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
inline int16_t readBE16Signed(const uint8_t* p) { return static_cast<int16_t>(readBE16(p)); }
inline int16_t readLE16Signed(const uint8_t* p) { return static_cast<int16_t>(readLE16(p)); }
inline uint32_t readLE32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | (static_cast<uint32_t>(p[1]) << 8) |
         (static_cast<uint32_t>(p[2]) << 16) | (static_cast<uint32_t>(p[3]) << 24);
}

inline void writeBE16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v >> 8);
  p[1] = static_cast<uint8_t>(v);
}
inline void writeLE16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(v >> 8);
}
inline void writeLE32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

}  // namespace serial_robot_driver::protocol
