#include "serial_robot_driver/device/device_set.h"

namespace serial_robot_driver::device {

namespace {

using protocol::FrameFamily;

// The bus is half duplex: our own servo requests come back as an echo and must be framed (and
// then ignored) rather than skipped byte by byte, or they could hide a response.
constexpr std::array<DeviceDescription, kDeviceCount> kDevices = {{
    {DeviceKind::kBase, "base", "Base", {FrameFamily::kBase, FrameFamily::kBase}, 1},
    {DeviceKind::kBody, "body", "Body", {FrameFamily::kTelemetry, FrameFamily::kTelemetry}, 1},
    {DeviceKind::kServoBus,
     "servo_bus",
     "Servo bus",
     {FrameFamily::kServoResponse, FrameFamily::kServoRequest},
     2},
}};

constexpr bool inKindOrder() {
  for (std::size_t i = 0; i < kDevices.size(); ++i) {
    if (static_cast<std::size_t>(kDevices[i].kind) != i) return false;
  }
  return true;
}
static_assert(inKindOrder(), "deviceSet() is indexed by DeviceKind");

}  // namespace

const std::array<DeviceDescription, kDeviceCount>& deviceSet() { return kDevices; }

const DeviceDescription& describe(DeviceKind kind) {
  return kDevices[static_cast<std::size_t>(kind)];
}

protocol::FramerConfig framerFor(const std::vector<DeviceKind>& devices,
                                 std::size_t telemetry_servo_count) {
  protocol::FramerConfig config;
  for (DeviceKind kind : devices) {
    const DeviceDescription& device = describe(kind);
    for (std::size_t i = 0; i < device.family_count; ++i) config.accept(device.families[i]);
  }
  config.telemetry_servo_count = telemetry_servo_count;
  return config;
}

}  // namespace serial_robot_driver::device
