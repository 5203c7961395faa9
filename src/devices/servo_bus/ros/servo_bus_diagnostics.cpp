// The servo bus's diagnostic statuses, wired to the updater: what they say is
// device::ServoBusStatus's and device::servoHealthStatus's.
#include <chrono>
#include <string>

#include "serial_robot_driver/devices/servo_bus/servo_bus_interface.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_status.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

void ServoBusInterface::addDiagnostics(diagnostic_updater::Updater& updater) {
  // Every polled servo has its status, also while health_rate is 0 (it may be tuned on).
  for (uint8_t id : bus_.config().polled_ids) {
    updater.add(
        "servo_bus servo " + std::to_string(id),
        [this, id](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnoseServo(id, s); });
  }
}

void ServoBusInterface::diagnoseServo(uint8_t id,
                                      diagnostic_updater::DiagnosticStatusWrapper& status) {
  const double health_rate = bus_.settings().health_rate;
  const std::vector<device::ServoHealthReport> health =
      health_rate > 0.0 ? bus_.health() : std::vector<device::ServoHealthReport>{};
  const device::ServoHealthReport* found = nullptr;
  for (const device::ServoHealthReport& report : health) {
    if (report.id == id) found = &report;
  }
  device::StatusReport report = device::servoHealthStatus(id, health_rate, found);
  const std::vector<device::ServoIdentityReport> identities = bus_.identities();
  const device::ServoIdentityReport* identity = nullptr;
  for (const device::ServoIdentityReport& candidate : identities) {
    if (candidate.id == id) identity = &candidate;
  }
  device::addServoIdentity(identity, &report);
  report.hardware_id = link_.options().path;
  writeStatusReport(report, status);
}

void ServoBusInterface::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  device::ServoBusSnapshot bus;
  bus.port = {link_.options().path, link_.connected()};
  bus.stats = client_.stats();
  bus.options = client_.options();
  bus.worker = bus_.stats();
  bus.moving_ids = bus_.movingIds();
  bus.motion_locked = bus_.motionLocked();
  bus.motion_refused_at_write = bus_.motionRefusedAtWrite();
  bus.pending_stops = bus_.pendingStops();
  bus.in_force = bus_.settings();
  bus.commands_rejected = commands_rejected_.load();
  writeStatusReport(status_.update(bus, std::chrono::steady_clock::now()), status);
}

}  // namespace serial_robot_driver::ros_layer
