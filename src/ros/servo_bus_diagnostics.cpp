// The servo bus's diagnostic statuses: the bus as a whole (transactions, the poll's asked vs
// achieved rate, the e-stop's lock and the stops not yet confirmed) and one status per polled
// servo (its health against its own limits).
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

#include "serial_robot_driver/ros/servo_bus_interface.h"

namespace serial_robot_driver::ros_layer {

void diagnoseServoHealth(uint8_t id, const device::ServoHealthReport* found,
                         diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  const std::string name = "servo " + std::to_string(id);
  if (!found || !found->polled) {
    status.summary(DiagnosticStatus::OK, name + ": no health poll yet");
    return;
  }
  const device::ServoHealthReport& report = *found;
  status.add("online", report.online);
  if (!report.online) {
    status.summary(DiagnosticStatus::ERROR, name + " does not answer: " + report.last_error);
    return;
  }
  const device::ServoReadings& r = report.readings;
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
    case device::HealthLevel::kOk:
      status.summary(DiagnosticStatus::OK, name + " ok");
      break;
    case device::HealthLevel::kWarn:
      status.summary(DiagnosticStatus::WARN, report.assessment.message);
      break;
    case device::HealthLevel::kError:
      status.summary(DiagnosticStatus::ERROR, report.assessment.message);
      break;
  }
  if (report.overheated) {
    status.mergeSummary(DiagnosticStatus::ERROR, "relaxed, moves refused until it has cooled");
  }
}

void ServoBusInterface::addDiagnostics(diagnostic_updater::Updater& updater) {
  // Every polled servo has its status, also while health_rate is 0 (it may be tuned on).
  for (uint8_t id : bus_.config().polled_ids) {
    updater.add("servo_bus servo " + std::to_string(id),
                [this, id](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnoseServo(id, s); });
  }
}

void ServoBusInterface::diagnoseServo(uint8_t id, diagnostic_updater::DiagnosticStatusWrapper& status) {
  status.hardware_id = link_.options().path;
  if (bus_.settings().health_rate <= 0.0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   "servo " + std::to_string(id) + ": health poll off (~servo_bus/health_rate 0)");
    return;
  }
  std::optional<device::ServoHealthReport> found;
  for (const device::ServoHealthReport& report : bus_.health()) {
    if (report.id == id) found = report;
  }
  diagnoseServoHealth(id, found ? &*found : nullptr, status);
}

void ServoBusInterface::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const device::ServoBusStats stats = client_.stats();
  if (link_.connected()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   std::to_string(stats.transactions) + " transactions, " +
                       std::to_string(stats.timeouts) + " timeouts");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "servo bus port is not connected");
  }
  status.hardware_id = link_.options().path;
  status.add("port", link_.options().path);
  status.add("connected", link_.connected());
  status.add("transactions", stats.transactions);
  status.add("commands without answer", stats.commands);
  status.add("timeouts", stats.timeouts);
  status.add("retries", stats.retries);
  status.add("mismatched answers", stats.mismatched);
  status.add("garbled answers", stats.garbled);
  status.add("echoes skipped", stats.echoes);
  status.addf("last latency (ms)", "%.2f", stats.last_latency_ms);
  status.addf("max latency (ms)", "%.2f", stats.max_latency_ms);
  const device::ServoBusOptions options = client_.options();
  status.add("timeout (ms)", static_cast<int>(options.timeout.count()));
  status.add("retries per transaction", options.retries);
  status.add("dangerous writes armed", options.allow_dangerous_writes);

  const device::ServoBusWorkerStats worker = bus_.stats();
  std::string offline;
  for (uint8_t id : worker.offline_ids) {
    offline += (offline.empty() ? "" : ", ") + std::to_string(id);
  }
  status.add("servo_states published", worker.angles_polled);
  status.add("polled servos offline", offline.empty() ? std::string("none") : offline);
  status.add("servo_commands moves sent", worker.moves_sent);
  status.add("servo_commands rejected", commands_rejected_.load());
  status.add("servo_commands moves failed", worker.moves_failed);
  std::string moving;
  for (uint8_t id : bus_.movingIds()) moving += (moving.empty() ? "" : ", ") + std::to_string(id);
  status.add("servos set moving", moving.empty() ? std::string("none") : moving);
  status.add("motion locked (e_stop)", bus_.motionLocked());
  status.add("motion frames refused when written", bus_.motionRefusedAtWrite());
  std::string unconfirmed;
  for (const device::PendingStopReport& stop : bus_.pendingStops()) {
    unconfirmed += (unconfirmed.empty() ? "" : "; ") + servoJointName(stop.id) + ": " + stop.why;
  }
  status.add("stops not yet confirmed", unconfirmed.empty() ? std::string("none") : unconfirmed);
  if (!unconfirmed.empty()) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::ERROR,
                        "stop not yet known to have reached " + unconfirmed);
  }
  const device::ServoBusConfig in_force = bus_.settings();
  status.add("on shutdown", device::toString(in_force.on_shutdown));
  status.add("health polls per second", in_force.health_rate);
  status.add("protect", in_force.protect);
  if (!offline.empty() && link_.connected()) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN,
                        "polled servos not answering: " + offline);
  }

  // Asked vs achieved: the state_rate in force for every answering polled servo, against the
  // angles read over the window. A line too slow for what was asked (or service calls taking
  // the bus) shows here rather than as a silently lower rate.
  // The achieved rate is measured over at least kRateWindowS, so one slow transaction (a silent
  // servo's timeout, a long service call) does not flag a line that keeps up on average.
  constexpr double kRateWindowS = 2.0;
  const auto now = std::chrono::steady_clock::now();
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
  status.addf("servo_states asked (per s)", "%.1f", asked);
  if (achieved_rate_ < 0) return;  // the first window is not over yet
  status.addf("servo_states achieved (per s)", "%.1f", achieved_rate_);
  // 10 % of slack for the window's own jitter; a saturated line falls far below it.
  if (link_.connected() && asked > 0 && achieved_rate_ < 0.9 * asked) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "servo_states: %.0f reads/s asked, the bus delivers %.0f/s (the line or "
                  "service calls are the limit: lower ~servo_bus/state_rate or raise the baud)",
                  asked, achieved_rate_);
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, text);
  }
}

}  // namespace serial_robot_driver::ros_layer
