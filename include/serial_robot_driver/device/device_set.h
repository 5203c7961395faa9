// The robot's devices, described once: the driver's node, its parameters, the bag replay, the
// simulator and the diagnostics configuration all walk this set. A fourth device is one row here
// plus its own files (codec, device class, ROS interface, simulator part).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"

namespace serial_robot_driver::device {

enum class DeviceKind : uint8_t { kBase, kBody, kServoBus };
constexpr std::size_t kDeviceCount = 3;

struct DeviceDescription {
  DeviceKind kind;
  /// The parameter namespace (~<name>/enabled, ~<name>/port, ~<name>/baud), the diagnostic
  /// status ("<node>: <name>") and the simulator's name for its link.
  const char* name;
  /// For people: the diagnostics analyzer's path.
  const char* title;
  /// The frame families the driver's framer must accept on the device's port.
  std::array<protocol::FrameFamily, 2> families;
  std::size_t family_count;
};

/// In start and shutdown order: the base first, so its zero-speed frame goes out before anything
/// else stops.
const std::array<DeviceDescription, kDeviceCount>& deviceSet();
const DeviceDescription& describe(DeviceKind kind);

/// What the driver's framer accepts on a port shared by `devices`.
protocol::FramerConfig framerFor(const std::vector<DeviceKind>& devices,
                                 std::size_t telemetry_servo_count);

}  // namespace serial_robot_driver::device
