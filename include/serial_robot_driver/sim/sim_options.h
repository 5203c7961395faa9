// What the simulated robot runs: its devices, their ports and the faults it injects. Filled by
// the robot_sim command line (command_line.h) or directly by tests; a device's typed settings are
// read and written through its own accessor (<name>Config(options) in its <name>_sim.h).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::sim {

/// Faults injected into what the simulator sends. All probabilities are per frame, 0..1.
struct FaultOptions {
  uint32_t seed = 1;
  double garbage_rate_hz = 0.0;  ///< junk bursts per second per port (Poisson); any byte values
  double corrupt_rate = 0.0;     ///< a sent frame gets its checksum byte inverted
  double drop_rate = 0.0;        ///< a sent frame loses one random byte
  double unplug_every_s = 0.0;   ///< 0: never unplug
  double unplug_duration_s = 1.0;
};

struct SimOptions {
  /// Symlink shared by every device without a link of its own ("": no symlink, print the path).
  std::string link;
  FaultOptions faults;
  /// 0: bytes move as fast as the pty takes them. Otherwise the line's baud rate: each port sends
  /// and receives at most pace_baud / 10 bytes per second (start + 8 data + stop bits), so the
  /// timing seen through the simulator matches a real wire.
  unsigned pace_baud = 0;
  std::string stats_file;  ///< written atomically every stats_period_s and at stop(); "" = none
  double stats_period_s = 1.0;
  /// Human-readable events from the sim thread (unplug, replug with the new pty path).
  std::function<void(const std::string&)> on_event;

  /// The settings of the registered device `name`, made with its defaults on first use (hosted
  /// if the device is by default). Throws std::invalid_argument for a name nobody registered.
  HostedDeviceOptions& device(const std::string& name);
  /// Whether robot_sim hosts the device `name`.
  bool hosts(const std::string& name) const;
  /// The settings of `name` if any were made, else null.
  const HostedDeviceOptions* findDevice(const std::string& name) const;

 private:
  std::map<std::string, HostedDeviceOptions> devices_;
};

}  // namespace serial_robot_driver::sim
