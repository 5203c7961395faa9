#include "serial_robot_driver/devices/servo_bus/servo_bus_status.h"

#include <cstdio>

namespace serial_robot_driver::devices::servo_bus {

core::StatusReport servoHealthStatus(uint8_t id, double health_rate,
                                     const ServoHealthReport* found) {
  core::StatusReport status;
  const std::string name = "servo " + std::to_string(id);
  if (health_rate <= 0.0) {
    status.summary(core::StatusLevel::kOk, name + ": health poll off (~servo_bus/health_rate 0)");
    return status;
  }
  if (!found || !found->polled) {
    status.summary(core::StatusLevel::kOk, name + ": no health poll yet");
    return status;
  }
  const ServoHealthReport& report = *found;
  status.add("online", report.online);
  if (!report.online) {
    status.summary(core::StatusLevel::kError, name + " does not answer: " + report.last_error);
    return status;
  }
  const ServoReadings& r = report.readings;
  status.add("voltage (mV)", r.voltage_mv);
  status.add("current (mA)", r.current_ma);
  status.add("power (mW)", r.power_mw);
  status.add("temperature (degC)", r.temperature_c);
  status.add("servo_status", r.status);
  if (report.limits_known) {
    status.add("over_volt_low (mV)", report.limits.over_volt_low_mv);
    status.add("over_volt_high (mV)", report.limits.over_volt_high_mv);
    status.add("over_temperature (degC)", report.limits.over_temperature_c);
    status.add("over_power (mW)", report.limits.over_power_mw);
    status.add("over_current (mA)", report.limits.over_current_ma);
  } else {
    status.add("limits", "not read yet");
  }
  status.add("relaxed for its temperature (protect)", report.overheated);
  switch (report.assessment.level) {
    case HealthLevel::kOk:
      status.summary(core::StatusLevel::kOk, name + " ok");
      break;
    case HealthLevel::kWarn:
      status.summary(core::StatusLevel::kWarn, report.assessment.message);
      break;
    case HealthLevel::kError:
      status.summary(core::StatusLevel::kError, report.assessment.message);
      break;
  }
  if (report.overheated) {
    status.mergeSummary(core::StatusLevel::kError, "relaxed, moves refused until it has cooled");
  }
  return status;
}

void addServoIdentity(const ServoIdentityReport* found, core::StatusReport* status) {
  if (!found || !found->known) {
    status->add("identity", "not read yet (read once the servo answers)");
    return;
  }
  const ServoIdentity& identity = found->identity;
  status->add("servo_type", identity.servo_type);
  status->add("firmware_version", identity.firmware_version);
  status->add("serial_number", identity.serial_number);
  status->add("response_switch", static_cast<int>(identity.response_switch));
  status->add("angle limits", describeAngleLimits(identity));
  for (const std::string& warning : found->warnings) {
    status->mergeSummary(core::StatusLevel::kWarn, warning);
  }
}

namespace {

/// The summary by the port, its transaction counters and the options in force on it.
void addLink(const ServoBusSnapshot& bus, core::StatusReport* status) {
  const ServoBusStats& stats = bus.stats;
  if (bus.port.connected) {
    status->summary(core::StatusLevel::kOk, std::to_string(stats.transactions) + " transactions, " +
                                                std::to_string(stats.timeouts) + " timeouts");
  } else {
    status->summary(core::StatusLevel::kWarn, "servo bus port is not connected");
  }
  status->hardware_id = bus.port.path;
  status->add("port", bus.port.path);
  status->add("connected", bus.port.connected);
  status->add("transactions", stats.transactions);
  status->add("commands without answer", stats.commands);
  status->add("timeouts", stats.timeouts);
  status->add("retries", stats.retries);
  status->add("mismatched answers", stats.mismatched);
  status->add("garbled answers", stats.garbled);
  status->add("echoes skipped", stats.echoes);
  status->addf("last latency (ms)", "%.2f", stats.last_latency_ms);
  status->addf("max latency (ms)", "%.2f", stats.max_latency_ms);
  status->add("timeout (ms)", static_cast<int>(bus.options.timeout.count()));
  status->add("retries per transaction", bus.options.retries);
  status->add("dangerous writes armed", bus.options.allow_dangerous_writes);
}

/// The polls, the moves, the e-stop's stops not yet confirmed and the settings in force.
void addWorker(const ServoBusSnapshot& bus, core::StatusReport* status) {
  const ServoBusWorkerStats& worker = bus.worker;
  const std::string offline = servoIdList(worker.offline_ids);
  status->add("servo_states published", worker.angles_polled);
  status->add("polled servos offline", offline.empty() ? std::string("none") : offline);
  status->add("servo_commands moves sent", worker.moves_sent);
  status->add("servo_commands rejected", bus.commands_rejected);
  status->add("servo_commands moves failed", worker.moves_failed);
  const std::string moving = servoIdList(bus.moving_ids);
  status->add("servos set moving", moving.empty() ? std::string("none") : moving);
  status->add("motion locked (e_stop)", bus.motion_locked);
  status->add("motion frames refused when written", bus.motion_refused_at_write);
  std::string unconfirmed;
  for (const PendingStopReport& stop : bus.pending_stops) {
    unconfirmed += (unconfirmed.empty() ? "" : "; ") + servoJointName(stop.id) + ": " + stop.why;
  }
  status->add("stops not yet confirmed", unconfirmed.empty() ? std::string("none") : unconfirmed);
  if (!unconfirmed.empty()) {
    status->mergeSummary(core::StatusLevel::kError,
                         "stop not yet known to have reached " + unconfirmed);
  }
  status->add("on shutdown", toString(bus.in_force.on_shutdown));
  status->add("health polls per second", bus.in_force.health_rate);
  status->add("protect", bus.in_force.protect);
  if (!offline.empty() && bus.port.connected) {
    status->mergeSummary(core::StatusLevel::kWarn, "polled servos not answering: " + offline);
  }
}

}  // namespace

core::StatusReport ServoBusStatus::update(const ServoBusSnapshot& bus,
                                          std::chrono::steady_clock::time_point now) {
  core::StatusReport status;
  addLink(bus, &status);
  addWorker(bus, &status);
  addPollRate(bus, now, &status);
  return status;
}

void ServoBusStatus::addPollRate(const ServoBusSnapshot& bus,
                                 std::chrono::steady_clock::time_point now,
                                 core::StatusReport* status) {
  // Asked vs achieved: the state_rate in force for every answering polled servo, against the
  // angles read over the window. A line too slow for what was asked (or service calls taking
  // the bus) shows here rather than as a silently lower rate.
  const ServoBusWorkerStats& worker = bus.worker;
  const double asked = worker.asked_poll_rate;
  if (last_rate_check_ == std::chrono::steady_clock::time_point{}) {
    last_rate_check_ = now;
    polls_at_last_check_ = worker.angles_polled;
  }
  const double seconds = std::chrono::duration<double>(now - last_rate_check_).count();
  if (seconds >= kRateWindowS) {
    achieved_rate_ = static_cast<double>(worker.angles_polled - polls_at_last_check_) / seconds;
    polls_at_last_check_ = worker.angles_polled;
    last_rate_check_ = now;
  }
  status->addf("servo_states asked (per s)", "%.1f", asked);
  if (achieved_rate_ < 0) return;  // the first window is not over yet
  status->addf("servo_states achieved (per s)", "%.1f", achieved_rate_);
  if (bus.port.connected && asked > 0 && achieved_rate_ < kRateSlack * asked) {
    status->mergeSummaryf(core::StatusLevel::kWarn,
                          "servo_states: %.0f reads/s asked, the bus delivers %.0f/s (the line or "
                          "service calls are the limit: lower ~servo_bus/state_rate or raise the "
                          "baud)",
                          asked, achieved_rate_);
  }
}

}  // namespace serial_robot_driver::devices::servo_bus
