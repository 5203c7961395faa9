// What the simulated robot runs: its devices, their ports and the faults it injects. Filled by
// the robot_sim command line (command_line.h) or directly by tests.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_sim.h"
#include "serial_robot_driver/devices/body/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_sim.h"
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
  double servo_fault_rate = 0.0;  ///< a servo answer is garbled (half) or not sent (half)
};

struct SimOptions {
  /// Symlink shared by every device without a link of its own ("": no symlink, print the path).
  std::string link;
  /// Per-device links; devices whose effective links are equal share one pty.
  std::optional<std::string> base_link;
  std::optional<std::string> body_link;
  std::optional<std::string> servo_link;
  bool enable_base = true;
  bool enable_body = true;
  bool enable_servo_bus = true;
  BaseSimConfig base;
  BodySimConfig body;
  ServoBusSimConfig servo_bus;
  /// Other registered devices to host (--<name>; sim/sim_device_module.h), none by default.
  std::vector<HostedDeviceOptions> hosted;
  FaultOptions faults;
  /// 0: bytes move as fast as the pty takes them. Otherwise the line's baud rate: each port sends
  /// and receives at most pace_baud / 10 bytes per second (start + 8 data + stop bits), so the
  /// timing seen through the simulator matches a real wire.
  unsigned pace_baud = 0;
  std::string stats_file;  ///< written atomically every stats_period_s and at stop(); "" = none
  double stats_period_s = 1.0;
  /// Human-readable events from the sim thread (unplug, replug with the new pty path).
  std::function<void(const std::string&)> on_event;
};

}  // namespace serial_robot_driver::sim
