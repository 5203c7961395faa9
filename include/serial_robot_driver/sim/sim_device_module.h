// A device's simulator part, registered like its core module (device/device_module.h) and found
// by the same name: robot_sim hosts every registered device this way, on its own pty (its link
// flag) or the shared one, feeds it the frames of its DeviceModule::simulator_frames, writes back
// what it sends (with the faults it describes) and writes its counters into the stats. Defined in
// the device's folder (src/devices/<name>/sim/) as `kSimModule`; cmake/devices.cmake generates the
// registry.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/typed_value.h"
#include "serial_robot_driver/protocol/frame_family.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::sim {

/// One "key value" line of the stats file.
using StatsLine = std::pair<std::string, std::string>;

/// A stats line with the file's number format (3 decimals for floating-point values).
template <typename Value>
StatsLine statsLine(const std::string& key, const Value& value) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << value;
  return {key, out.str()};
}

/// What the ports saw, for a device's stats lines.
struct PortCounters {
  protocol::FramerStats own_port;   ///< the framer of the device's port (host -> sim)
  protocol::FramerStats all_ports;  ///< summed over every port
};

/// A device's counters in a stats snapshot: typed (its own struct, read through the device's own
/// accessor, <name>Stats(stats) in its <name>_sim.h) and as its stats-file lines.
struct DeviceSimStats {
  std::string name;
  core::TypedValue counters;
  std::vector<StatsLine> lines;
};

/// A simulated device robot_sim hosts: a state machine without I/O or threads.
class SimDevice {
 public:
  virtual ~SimDevice() = default;
  /// A verified frame of one of the device's simulator families, arrived on its port at `at`.
  virtual void handleFrame(const protocol::FrameFamily& family, const uint8_t* data,
                           std::size_t size, TimePoint at, Outbox* out) = 0;
  /// Periodic work up to `now` (frames it sends on its own); `world` is what the devices share.
  virtual void tick(TimePoint /*now*/, SimWorld& /*world*/, Outbox* /*out*/) {}
  /// When tick() has something to do next.
  virtual TimePoint nextEvent() const { return TimePoint::max(); }
  /// Its counters now; its stats-file keys are stable (tests and scripts read them).
  virtual DeviceSimStats stats(const PortCounters& ports) const = 0;
};

/// The settings of one device in SimOptions: whether robot_sim hosts it, where, and its values.
struct HostedDeviceOptions {
  std::string name;                 ///< DeviceModule::name
  bool enabled = false;             ///< created from SimDeviceModule::hosted_by_default
  std::optional<std::string> link;  ///< its own pty; none: the shared one (SimOptions::link)
  /// Values of its options that have no apply function, as given (option -> text).
  std::map<std::string, std::string> settings;
  /// Its typed settings (its <Name>SimConfig), made with their defaults on first use; reading
  /// them as another type throws std::logic_error.
  core::TypedValue config;

  template <typename Config>
  Config& configAs() {
    if (config.empty()) config = Config{};
    return config.as<Config>();
  }
  /// The defaults when nothing was set.
  template <typename Config>
  Config configAs() const {
    return config.empty() ? Config{} : config.as<Config>();
  }
};

/// One robot_sim flag a device declares: by default --<name>-<option> VALUE, or a full flag name.
struct SimDeviceOption {
  /// "latency-ms" (the flag is --<name>-latency-ms), or a whole flag such as "--turn-slip".
  std::string option;
  std::string value_name;  ///< "MS"; empty for a switch
  std::string help;
  /// Applies the value ("" for a switch) to the device's settings; returns "" or what is wrong.
  /// Null: the text is kept in HostedDeviceOptions::settings[option] for make() to read.
  std::function<std::string(const std::string& value, HostedDeviceOptions& device)> apply;
  /// The default --help shows (from default settings); null: none shown.
  std::function<std::string(const HostedDeviceOptions& defaults)> shown_default;
};

/// Declared with named fields (designated initialisers); a field left out is empty, false or null.
struct SimDeviceModule {
  /// The core module's name (DeviceModule::name).
  const char* name = nullptr;
  /// What it is, for robot_sim's --help ("lidar on a UART").
  const char* description = nullptr;
  /// True: simulated unless left out (--no-<name>); false: only when asked for (--<name>).
  bool hosted_by_default = false;
  /// Help of that switch ("leave the X out" / "simulate the X").
  const char* toggle_help = nullptr;
  /// Its own-pty flag (empty: --<name>-link; a device may keep a shorter one) and its help.
  const char* link_flag = "";
  const char* link_help = nullptr;
  /// Its random seed is the --seed value plus this (the seeded tests' results depend on it).
  uint32_t seed_offset = 0;
  /// What it sends: RobotSim keeps send counters for each (in this order) while it is hosted.
  std::vector<const OutputKind*> outputs;
  /// Builds the hosted device; throws std::invalid_argument for a bad setting.
  std::unique_ptr<SimDevice> (*make)(const HostedDeviceOptions& options, uint32_t seed,
                                     TimePoint now) = nullptr;
  /// Its counters while it is left out (all zero), so the stats file keeps the keys it always
  /// had; null: it writes none then.
  DeviceSimStats (*left_out_stats)(const PortCounters& ports) = nullptr;
  /// Its settings on the command line.
  std::vector<SimDeviceOption> options;
};

/// The registered devices' simulator parts, in the order of the devices (cmake/devices.cmake).
const std::vector<const SimDeviceModule*>& registeredSimDevices();
/// The simulator part of the device called `name`, or null.
const SimDeviceModule* findSimDevice(const std::string& name);
/// The command-line spelling of a device name: "a_b" -> "a-b".
std::string flagName(const std::string& device);
/// The flag of `module`'s `option`: "--<name>-<option>", or the option itself when it is a flag.
std::string optionFlag(const SimDeviceModule& module, const SimDeviceOption& option);
/// The flag that gives `module` its own pty.
std::string linkFlag(const SimDeviceModule& module);

}  // namespace serial_robot_driver::sim
