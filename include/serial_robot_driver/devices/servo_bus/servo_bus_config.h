// How a device::ServoBus is configured: its client's options, the polls, the shutdown action and
// the protection; retune() changes the tunable part at runtime. ROS-free.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_identity.h"
#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

namespace serial_robot_driver::devices::servo_bus {

/// What servos set moving get when the bus shuts down (before its port closes).
enum class ShutdownAction { kStop, kRelax, kNone };
/// "stop", "relax", "none"; nullopt for anything else.
std::optional<ShutdownAction> shutdownActionFromString(const std::string& text);
const char* toString(ShutdownAction action);

/// The part of the bus's configuration that can change while it runs (ServoBus::retune() takes it
/// over whole, with the client's ServoClientTuning).
struct ServoBusTuning {
  double poll_rate = 10.0;       ///< polls per second of each polled servo, > 0
  uint16_t relax_power_mw = 50;  ///< DAMPING power of relax()
  /// For each servo set spinning or moving: kStop a SPIN stop, kRelax relax(), kNone nothing.
  ShutdownAction on_shutdown = ShutdownAction::kStop;
  /// Health polls (voltage, current, power, temperature, status) per second of each polled
  /// servo, as background work between the angle polls; 0: none.
  double health_rate = 1.0;
  /// A servo at its own temperature limit is relaxed and its moves refused until it has cooled
  /// OverheatGuard::kCoolDownC below it.
  bool protect = false;
  /// Each polled servo's identity and settings are read once when it first answers (background
  /// work) and checked against `identity`. Off only where a test counts every frame the poll
  /// writes.
  bool read_identity = true;
  ServoIdentityChecks identity;
};

struct ServoBusConfig : ServoBusTuning {
  ServoBusOptions client;
  std::vector<uint8_t> polled_ids;  ///< servos whose angle is polled (servo_states)
};

}  // namespace serial_robot_driver::devices::servo_bus
