#include "serial_robot_driver/devices/servo_bus/servo_bus_diagnostics.h"

#include <chrono>
#include <vector>

namespace serial_robot_driver::devices::servo_bus {

core::StatusReport ServoBusDiagnostics::servoStatus(uint8_t id) const {
  const double health_rate = bus_.settings().health_rate;
  const std::vector<ServoHealthReport> health =
      health_rate > 0.0 ? bus_.health() : std::vector<ServoHealthReport>{};
  const ServoHealthReport* found = nullptr;
  for (const ServoHealthReport& report : health) {
    if (report.id == id) found = &report;
  }
  core::StatusReport report = servoHealthStatus(id, health_rate, found);
  const std::vector<ServoIdentityReport> identities = bus_.identities();
  const ServoIdentityReport* identity = nullptr;
  for (const ServoIdentityReport& candidate : identities) {
    if (candidate.id == id) identity = &candidate;
  }
  addServoIdentity(identity, &report);
  report.hardware_id = link_.options().path;
  return report;
}

core::StatusReport ServoBusDiagnostics::busStatus(uint64_t commands_rejected) {
  ServoBusSnapshot bus;
  bus.port = {link_.options().path, link_.connected()};
  bus.stats = bus_.client().stats();
  bus.options = bus_.client().options();
  bus.worker = bus_.stats();
  bus.moving_ids = bus_.movingIds();
  bus.motion_locked = bus_.motionLocked();
  bus.motion_refused_at_write = bus_.motionRefusedAtWrite();
  bus.pending_stops = bus_.pendingStops();
  bus.in_force = bus_.settings();
  bus.commands_rejected = commands_rejected;
  return status_.update(bus, std::chrono::steady_clock::now());
}

}  // namespace serial_robot_driver::devices::servo_bus
