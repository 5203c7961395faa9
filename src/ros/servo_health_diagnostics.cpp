// One bus servo's health as a diagnostic status (see ServoBusInterface::addDiagnostics).
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

}  // namespace serial_robot_driver::ros_layer
