// Every frame family of the registered devices (cmake/devices.cmake), once, in registration order:
// fuzz_framer selects among them with its input's first byte, bit i for family i, fuzz_decoders
// with its first byte's value (decoderSelector), and make_corpus writes its seeds' prefixes the
// same way.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device_module.h"

namespace fuzz_support {

inline const std::vector<serial_robot_driver::protocol::FrameFamily>& registeredFamilies() {
  static const std::vector<serial_robot_driver::protocol::FrameFamily> families = [] {
    std::vector<serial_robot_driver::protocol::FrameFamily> all;
    const auto add = [&all](const serial_robot_driver::protocol::FrameFamily& family) {
      for (const auto& known : all) {
        if (known == family) return;
      }
      all.push_back(family);
    };
    for (const auto* device : serial_robot_driver::core::registeredDevices()) {
      for (const auto& family : device->driver_frames) add(family);
      for (const auto& family : device->simulator_frames) add(family);
    }
    return all;
  }();
  return families;
}

/// The position of the family called `name` among registeredFamilies().
inline std::size_t familyIndex(const char* name) {
  const auto& families = registeredFamilies();
  for (std::size_t i = 0; i < families.size(); ++i) {
    if (std::strcmp(families[i].name, name) == 0) return i;
  }
  throw std::invalid_argument(std::string("no registered frame family ") + name);
}

/// The prefix bit of the family called `name` (bit 7 is fuzz_framer's reset flag).
inline uint8_t familyBit(const char* name) {
  const std::size_t index = familyIndex(name);
  if (index >= 7) {
    throw std::invalid_argument(std::string("frame family ") + name + " is not in bits 0..6");
  }
  return static_cast<uint8_t>(1u << index);
}

/// How fuzz_decoders reads its first byte: the family (byte % families) and the mode
/// (byte / families % kDecoderModes: 0 raw, 1 checksum fixed, 2 header, length, tail and checksum
/// fixed).
constexpr std::size_t kDecoderModes = 3;
inline uint8_t decoderSelector(const char* family, std::size_t mode) {
  return static_cast<uint8_t>(familyIndex(family) + registeredFamilies().size() * mode);
}

}  // namespace fuzz_support
