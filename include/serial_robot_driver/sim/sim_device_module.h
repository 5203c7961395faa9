// A device's simulator part, registered like its core module (device/device_module.h) and found
// by the same name: robot_sim hosts a registered device it does not know by name on its own pty
// (--<name>-link) or the shared one, feeds it the frames of its DeviceModule::simulator_frames,
// writes back what it answers and adds its counters to the stats. Defined in the device's folder
// (src/devices/<name>/sim/) as `kSimModule`; cmake/devices.cmake generates the registry.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/protocol/frame_family.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::sim {

/// Frames a hosted device wants written on its port, in order.
using HostedOutbox = std::vector<std::vector<uint8_t>>;

/// A simulated device robot_sim hosts through the registry: a state machine without I/O or
/// threads, like the built-in models (sim_types.h).
class SimDevice {
 public:
  virtual ~SimDevice() = default;
  /// A verified frame of one of the device's simulator families, arrived on its port at `at`.
  virtual void handleFrame(const protocol::FrameFamily& family, const uint8_t* data,
                           std::size_t size, TimePoint at, HostedOutbox* out) = 0;
  /// Periodic work up to `now` (frames it sends on its own).
  virtual void tick(TimePoint /*now*/, HostedOutbox* /*out*/) {}
  /// When tick() has something to do next.
  virtual TimePoint nextEvent() const { return TimePoint::max(); }
  /// "key value" lines for the stats file, keys prefixed with the device's name.
  virtual std::vector<std::pair<std::string, std::string>> statsLines() const = 0;
};

/// A setting of a hosted device on robot_sim's command line: --<name>-<option> VALUE.
struct SimDeviceOption {
  const char* option;      ///< "latency-ms"
  const char* value_name;  ///< "MS"
  const char* help;
};

/// What robot_sim hosts: one device with its link and its settings (--<name>-<option> values).
struct HostedDeviceOptions {
  std::string name;                 ///< DeviceModule::name
  std::optional<std::string> link;  ///< its own pty; none: the shared one (SimOptions::link)
  std::map<std::string, std::string> settings;  ///< option -> value as given
};

struct SimDeviceModule {
  /// The core module's name (DeviceModule::name).
  const char* name;
  /// Builds the hosted device; throws std::invalid_argument for a bad setting. Null for the
  /// built-in models robot_sim still hosts by name (base, body, servo bus: sim_options.h).
  std::unique_ptr<SimDevice> (*make)(const HostedDeviceOptions& options, uint32_t seed,
                                     TimePoint now);
  /// Its --<name>-<option> settings.
  std::vector<SimDeviceOption> options;
};

/// The registered devices' simulator parts, in the order of the devices (cmake/devices.cmake).
const std::vector<const SimDeviceModule*>& registeredSimDevices();
/// The simulator part of the device called `name`, or null.
const SimDeviceModule* findSimDevice(const std::string& name);
/// The command-line spelling of a device name: "servo_bus" -> "servo-bus".
std::string flagName(const std::string& device);

}  // namespace serial_robot_driver::sim
