#include "serial_robot_driver/devices/servo_bus/servo_poller.h"

#include <algorithm>
#include <string>
#include <utility>

namespace serial_robot_driver::devices::servo_bus {

namespace {

/// How often a polled servo is asked again while its port is down (reopened every
/// reconnect_interval, 1 s by default).
constexpr std::chrono::milliseconds kPortDownRetry{100};

const std::vector<const char*> kReadingNames = {"voltage", "current", "power", "temperature",
                                                "servo_status"};
const std::vector<const char*> kLimitNames = {"over_volt_low", "over_volt_high", "over_temperature",
                                              "over_power", "over_current"};

core::Clock::duration periodOf(double rate_hz) {
  return std::chrono::duration_cast<core::Clock::duration>(
      std::chrono::duration<double>(1.0 / rate_hz));
}

}  // namespace

ServoPoller::ServoPoller(const std::vector<uint8_t>& ids, const ServoBusConfig& settings,
                         ServoBusClient& client, const ServoBusEvents& events,
                         core::LoopClock& clock, std::mutex& mutex, Hooks hooks)
    : settings_(settings),
      client_(client),
      events_(events),
      clock_(clock),
      mutex_(mutex),
      hooks_(std::move(hooks)),
      poll_period_(periodOf(settings.poll_rate)),
      read_identity_(settings.read_identity) {
  const core::Clock::time_point now = clock_.now();
  for (uint8_t id : ids) {
    PolledServo servo;
    servo.id = id;
    servo.next_poll = now;
    servo.identity.id = id;
    polled_.push_back(servo);
  }
  // Every polled servo has a health entry, so a health_rate turned on at runtime finds them.
  if (settings.health_rate > 0.0) health_period_ = periodOf(settings.health_rate);
  for (uint8_t id : ids) {
    HealthServo servo;
    servo.report.id = id;
    servo.next_poll = now;
    health_.push_back(servo);
  }
}

core::Clock::time_point ServoPoller::nextPollLocked() const {
  core::Clock::time_point next = nextHealthPollLocked();
  for (const PolledServo& servo : polled_) {
    next = std::min({next, servo.next_poll, servo.identity_due});
  }
  return next;
}

void ServoPoller::pollDue(std::unique_lock<std::mutex>& lock) {
  const core::Clock::time_point now = clock_.now();
  // A servo's identity first: read once, before its readings are judged.
  if (auto identity_due = identityDueLocked(now); identity_due != polled_.end()) {
    PolledServo& servo = *identity_due;
    lock.unlock();
    readIdentityOnce(servo);  // the schedule is only changed by this thread
    lock.lock();
    return;
  }
  // Health polls are background work of a second kind, due at their own (lower) rate.
  if (nextHealthPollLocked() <= now) {
    const auto first = std::min_element(
        health_.begin(), health_.end(),
        [](const HealthServo& a, const HealthServo& b) { return a.next_poll < b.next_poll; });
    const auto index = static_cast<std::size_t>(first - health_.begin());
    lock.unlock();
    pollHealthOnce(index);
    lock.lock();
    return;
  }
  // The servo whose poll is due first.
  auto due = std::min_element(
      polled_.begin(), polled_.end(),
      [](const PolledServo& a, const PolledServo& b) { return a.next_poll < b.next_poll; });
  if (due == polled_.end() || now < due->next_poll) return;
  PolledServo& servo = *due;
  lock.unlock();
  pollAngleOnce(servo);  // the schedule is only changed by this thread; the mutex for readers
  lock.lock();
}

void ServoPoller::retuneLocked(double poll_rate, double health_rate) {
  poll_period_ = periodOf(poll_rate);
  const core::Clock::time_point now = clock_.now();
  const core::Clock::time_point soonest = now + poll_period_;
  for (PolledServo& servo : polled_) {
    // A servo in back-off keeps its back-off; the others are due within the new period.
    if (servo.backoff.count() == 0) servo.next_poll = std::min(servo.next_poll, soonest);
  }
  const bool health_was_off = health_period_.count() == 0;
  health_period_ = health_rate > 0.0 ? periodOf(health_rate) : core::Clock::duration(0);
  for (HealthServo& servo : health_) {
    servo.next_poll = health_was_off ? now : std::min(servo.next_poll, now + health_period_);
  }
}

const ServoHealthReport* ServoPoller::overheatedLocked(uint8_t id) const {
  for (const HealthServo& servo : health_) {
    if (servo.report.id == id && servo.report.overheated) return &servo.report;
  }
  return nullptr;
}

void ServoPoller::addStatsLocked(ServoBusWorkerStats* stats) const {
  stats->angles_polled = angles_polled_;
  for (const PolledServo& servo : polled_) {
    if (servo.backoff.count() > 0) stats->offline_ids.push_back(servo.id);
  }
  const double poll_rate = 1.0 / std::chrono::duration<double>(poll_period_).count();
  stats->asked_poll_rate =
      poll_rate * static_cast<double>(polled_.size() - stats->offline_ids.size());
}

void ServoPoller::pollAngleOnce(PolledServo& servo) {
  ServoAngleSample sample;
  sample.id = servo.id;
  const ServoStatus status =
      client_.readAngle(servo.id, &sample.angle_deg, &sample.arrival, BusPriority::kBackground);
  if (status.error == ServoError::kPreempted) return;  // a stop went first: due again at once
  const core::Clock::time_point now = clock_.now();
  bool went_silent = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status.error == ServoError::kNotConnected || status.error == ServoError::kShutdown) {
      // The port is down, not the servo: ask again at the poll rate, but no more often than
      // kPortDownRetry, so a down port at a high state_rate does not keep the worker busy.
      servo.next_poll = now + std::max<core::Clock::duration>(poll_period_, kPortDownRetry);
      return;
    }
    if (!status.ok()) {
      went_silent = servo.backoff.count() == 0;
      servo.backoff = went_silent ? kFirstBackoff : std::min(servo.backoff * 2, kMaxBackoff);
      servo.next_poll = now + servo.backoff;
    } else {
      servo.backoff = std::chrono::milliseconds(0);
      // It answers: its identity is read once, as soon as the bus has time for it.
      if (read_identity_ && !servo.identity.known &&
          servo.identity_due == core::Clock::time_point::max())
        servo.identity_due = now;
      // Keep the rate without drifting; after a stall, start again from now.
      servo.next_poll = std::max(servo.next_poll + poll_period_, now);
      ++angles_polled_;
    }
  }
  if (!status.ok()) {
    if (went_silent && events_.on_servo_silent) {
      events_.on_servo_silent(servo.id, status, servo.backoff);
    }
    return;
  }
  if (events_.on_angle) events_.on_angle(sample);
}

std::vector<ServoPoller::PolledServo>::iterator ServoPoller::identityDueLocked(
    core::Clock::time_point now) {
  auto due = std::min_element(
      polled_.begin(), polled_.end(),
      [](const PolledServo& a, const PolledServo& b) { return a.identity_due < b.identity_due; });
  return due != polled_.end() && due->identity_due <= now ? due : polled_.end();
}

void ServoPoller::readIdentityOnce(PolledServo& servo) {
  ServoIdentity identity;
  // Background work: a service or a stop never waits for more than one of these reads. The
  // protection limits are the health poll's to read.
  const ServoStatus status =
      readServoIdentity(client_, servo.id, BusPriority::kBackground, false, &identity);
  // Shutting down, or a stop went first: due again as it was.
  if (status.error == ServoError::kShutdown || status.error == ServoError::kPreempted) return;
  ServoIdentityReport report;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const core::Clock::time_point now = clock_.now();
    if (status.error == ServoError::kNotConnected) {
      servo.identity_due = now + kPortDownRetry;  // the port, not the servo
      return;
    }
    if (!status.ok()) {
      // Silent or garbled: asked again later, quietly (the angle poll reports a silent servo).
      servo.identity_backoff = servo.identity_backoff.count() == 0
                                   ? kFirstBackoff
                                   : std::min(servo.identity_backoff * 2, kMaxBackoff);
      servo.identity_due = now + servo.identity_backoff;
      return;
    }
    servo.identity.known = true;
    servo.identity.identity = identity;
    servo.identity.warnings = identityWarnings(servo.id, identity, settings_.identity);
    servo.identity_due = core::Clock::time_point::max();  // read once
    report = servo.identity;
  }
  if (events_.on_identity) events_.on_identity(report);
}

std::vector<ServoIdentityReport> ServoPoller::identities() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ServoIdentityReport> reports;
  if (!read_identity_) return reports;
  for (const PolledServo& servo : polled_) reports.push_back(servo.identity);
  return reports;
}

core::Clock::time_point ServoPoller::nextHealthPollLocked() const {
  core::Clock::time_point next = core::Clock::time_point::max();
  if (health_period_.count() == 0) return next;  // health_rate 0: off
  for (const HealthServo& servo : health_) next = std::min(next, servo.next_poll);
  return next;
}

std::vector<ServoHealthReport> ServoPoller::health() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ServoHealthReport> reports;
  if (health_period_.count() == 0) return reports;
  for (const HealthServo& servo : health_) reports.push_back(servo.report);
  return reports;
}

ServoStatus ServoPoller::readHealthParams(uint8_t id, const std::vector<const char*>& names,
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

void ServoPoller::pollHealthOnce(std::size_t index) {
  // Only this thread changes health_; a copy of the entry is worked on and stored back under
  // mutex_ for health() readers.
  HealthServo servo;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    servo = health_[index];
  }
  const uint8_t id = servo.report.id;
  std::vector<int64_t> values;
  ServoStatus status = silentOnAnglePoll(id)
                           ? ServoStatus{ServoError::kTimeout, "does not answer the angle poll"}
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
  servo.report.polled = true;
  servo.report.online = status.ok();
  servo.report.last_error = status.ok() ? std::string() : status.message;
  const bool overheat_changed = status.ok() && assessReadings(values, &servo);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    servo.next_poll = std::max(servo.next_poll + health_period_, clock_.now());
    health_[index] = servo;
    if (servo.report.overheated) {
      // Its queued moves are dropped: none may follow the relax.
      hooks_.drop_queued_moves_locked(id);
    }
  }
  if (overheat_changed && servo.report.overheated) relaxOverheated(id);
  if (overheat_changed && events_.on_overheat) events_.on_overheat(servo.report);
}

bool ServoPoller::silentOnAnglePoll(uint8_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  bool silent = false;
  for (const PolledServo& polled : polled_) silent |= polled.id == id && polled.backoff.count() > 0;
  return silent;
}

bool ServoPoller::assessReadings(const std::vector<int64_t>& values, HealthServo* servo) {
  ServoHealthReport& report = servo->report;
  report.readings = {values[0], values[1], values[2], values[3], values[4]};
  report.assessment = report.limits_known ? assessHealth(report.id, report.readings, report.limits)
                                          : HealthAssessment{};
  bool protect = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    protect = settings_.protect;
  }
  if (!protect || !report.limits_known) return false;
  const bool overheated =
      servo->guard.update(report.readings.temperature_c, report.limits.over_temperature_c);
  const bool changed = overheated != report.overheated;
  report.overheated = overheated;
  return changed;
}

void ServoPoller::relaxOverheated(uint8_t id) {
  // A safety action: let through whatever the gate says.
  uint16_t relax_power_mw = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    relax_power_mw = settings_.relax_power_mw;
  }
  client_.damping(id, relax_power_mw, false, FrameGate::kSafetyAction);
  hooks_.relaxed(id);
}

}  // namespace serial_robot_driver::devices::servo_bus
