// The ServoBus's health poll: voltage, current, power, temperature and status of each polled
// servo, as background work on the worker thread between the angle polls (each read takes the bus
// only while no caller waits for it); the servo's own limits, read once when it first answers;
// and ~servo_bus/protect, which relaxes a servo at its temperature limit.
#include <algorithm>

#include "serial_robot_driver/device/servo_bus.h"

namespace serial_robot_driver::device {

namespace {

const std::vector<const char*> kReadingNames = {"voltage", "current", "power", "temperature",
                                                "servo_status"};
const std::vector<const char*> kLimitNames = {"over_volt_low", "over_volt_high",
                                              "over_temperature", "over_power", "over_current"};

}  // namespace

Clock::time_point ServoBus::nextHealthPoll() const {
  Clock::time_point next = Clock::time_point::max();
  if (health_period_.count() == 0) return next;  // health_rate 0: off
  for (const HealthServo& servo : health_) next = std::min(next, servo.next_poll);
  return next;
}

std::vector<ServoHealthReport> ServoBus::health() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ServoHealthReport> reports;
  if (health_period_.count() == 0) return reports;
  for (const HealthServo& servo : health_) reports.push_back(servo.report);
  return reports;
}

ServoStatus ServoBus::readHealthParams(uint8_t id, const std::vector<const char*>& names,
                                       std::vector<int64_t>* values) {
  values->clear();
  for (const char* name : names) {
    ServoParamValue value;
    const ServoStatus status = client_.readParam(id, name, &value, BusPriority::kBackground);
    if (!status.ok()) return status;
    values->push_back(value.value);
  }
  return {};
}

void ServoBus::pollHealthOnce(std::size_t index) {
  // Only this thread changes health_; a copy of the entry is worked on and stored back under
  // mutex_ for health() readers.
  HealthServo servo;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    servo = health_[index];
  }
  const uint8_t id = servo.report.id;
  bool silent = false;  // the angle poll has it in back-off: no bus time for a silent servo
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const PolledServo& polled : polled_) silent |= polled.id == id && polled.backoff.count() > 0;
  }
  std::vector<int64_t> values;
  ServoStatus status = silent ? ServoStatus{ServoError::kTimeout, "does not answer the angle poll"}
                              : readHealthParams(id, kReadingNames, &values);
  // Shutting down, or a stop went first: the poll is due again as it was.
  if (status.error == ServoError::kShutdown || status.error == ServoError::kPreempted) return;
  if (status.ok() && !servo.report.limits_known) {
    std::vector<int64_t> limits;
    if (readHealthParams(id, kLimitNames, &limits).ok()) {
      servo.report.limits = {limits[0], limits[1], limits[2], limits[3], limits[4]};
      servo.report.limits_known = true;
    }
  }
  bool overheat_changed = false;
  servo.report.polled = true;
  servo.report.online = status.ok();
  servo.report.last_error = status.ok() ? std::string() : status.message;
  if (status.ok()) {
    servo.report.readings = {values[0], values[1], values[2], values[3], values[4]};
    servo.report.assessment = servo.report.limits_known
                                  ? assessHealth(id, servo.report.readings, servo.report.limits)
                                  : HealthAssessment{};
    if (settings().protect && servo.report.limits_known) {
      const bool overheated = servo.guard.update(servo.report.readings.temperature_c,
                                                 servo.report.limits.over_temperature_c);
      overheat_changed = overheated != servo.report.overheated;
      servo.report.overheated = overheated;
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    servo.next_poll = std::max(servo.next_poll + health_period_, clock_->now());
    health_[index] = servo;
    if (servo.report.overheated) {
      // Its queued moves are dropped: none may follow the relax.
      dropQueuedMovesLocked(id);
    }
  }
  if (overheat_changed && servo.report.overheated) {
    // A safety action: let through whatever the gate says.
    client_.damping(id, settings().relax_power_mw, false, FrameGate::kSafetyAction);
    noteMotion(id, false);
  }
  if (overheat_changed && events_.on_overheat) events_.on_overheat(servo.report);
}

}  // namespace serial_robot_driver::device
