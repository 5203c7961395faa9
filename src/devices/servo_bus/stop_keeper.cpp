#include "serial_robot_driver/devices/servo_bus/stop_keeper.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

namespace serial_robot_driver::devices::servo_bus {

namespace {

/// A servo silent after its stop is asked again after a back-off doubling up to this.
constexpr std::chrono::milliseconds kLongestStopBackoff{2000};

std::chrono::milliseconds stopBackoff(int written) {
  const int doublings = std::clamp(written - 1, 0, 5);
  return std::min(StopKeeper::kStopRetry * (1 << doublings), kLongestStopBackoff);
}

}  // namespace

StopKeeper::StopKeeper(ServoBusClient& client, const ServoBusEvents& events, core::LoopClock& clock,
                       std::mutex& mutex, std::function<void(uint8_t id)> on_written_locked)
    : client_(client),
      events_(events),
      clock_(clock),
      mutex_(mutex),
      on_written_locked_(std::move(on_written_locked)) {}

void StopKeeper::armLocked(uint8_t id, core::Clock::time_point now, bool repeat) {
  PendingStop& stop = stops_[id];
  stop.phase = PendingStop::Phase::kWrite;
  stop.due = now;
  stop.repeat = repeat;
  stop.at_rest = false;  // seen at rest again before it is no longer pending
}

void StopKeeper::rearmAllLocked(core::Clock::time_point now) {
  for (auto& [id, stop] : stops_) armLocked(id, now, stop.repeat);
}

void StopKeeper::releaseLocked() {
  for (auto it = stops_.begin(); it != stops_.end();) {
    it->second.repeat = false;
    // A stop that never went out (the port was down) still goes out: a release restarts nothing.
    it = it->second.written > 0 ? stops_.erase(it) : std::next(it);
  }
  if (stops_.empty()) endUrgentLocked();
}

void StopKeeper::endRepeatsLocked() {
  for (auto& [id, stop] : stops_) stop.repeat = false;
}

void StopKeeper::renameLocked(uint8_t from, uint8_t to) {
  auto it = stops_.find(from);
  if (it == stops_.end() || from == to) return;
  stops_[to] = it->second;
  stops_.erase(from);
}

bool StopKeeper::portDownLocked() const {
  return std::all_of(stops_.begin(), stops_.end(),
                     [](const auto& entry) { return entry.second.port_down; });
}

std::vector<std::pair<uint8_t, std::string>> StopKeeper::unconfirmedLocked() const {
  std::vector<std::pair<uint8_t, std::string>> unconfirmed;
  for (const auto& [id, stop] : stops_) {
    if (!stop.at_rest) unconfirmed.push_back({id, stop.why});
  }
  return unconfirmed;
}

void StopKeeper::askUrgent() {
  // Under mutex_, so the flag and the client's reservation change together.
  std::lock_guard<std::mutex> lock(mutex_);
  urgent_asked_ = true;
  client_.requestUrgent();
}

void StopKeeper::endUrgentLocked() {
  if (!std::exchange(urgent_asked_, false)) return;
  client_.endUrgent();  // takes only the client's own locks
}

core::Clock::time_point StopKeeper::nextWorkLocked() const {
  // The bus is reserved for stops (askUrgent): the worker must see to it now, even when the stop
  // it was asked for is gone meanwhile (released, superseded), or every caller would wait.
  if (urgent_asked_) return core::Clock::time_point::min();
  core::Clock::time_point next = core::Clock::time_point::max();
  for (const auto& [id, stop] : stops_) next = std::min(next, stop.due);
  return next;
}

std::vector<PendingStopReport> StopKeeper::reports() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<PendingStopReport> reports;
  for (const auto& [id, stop] : stops_) {
    if (!stop.at_rest) reports.push_back({id, stop.written, stop.why});
  }
  return reports;
}

bool StopKeeper::workOnce(std::unique_lock<std::mutex>& lock, StopPace pace) {
  const core::Clock::time_point now = clock_.now();
  const auto due = [&](const PendingStop& stop) {
    return pace == StopPace::kNow || stop.due <= now;
  };
  for (const auto& [id, stop] : stops_) {
    if (stop.phase == PendingStop::Phase::kWrite && due(stop)) {
      writeDue(lock, pace);
      return true;
    }
  }
  // Nothing to write: the bus is no longer reserved.
  endUrgentLocked();
  for (const auto& [id, stop] : stops_) {
    if (due(stop)) {
      lookAtStoppedServo(lock, id, pace);
      return true;
    }
  }
  return false;
}

void StopKeeper::writeDue(std::unique_lock<std::mutex>& lock, StopPace pace) {
  std::vector<uint8_t> ids;
  const core::Clock::time_point now = clock_.now();
  for (const auto& [id, stop] : stops_) {
    if (stop.phase == PendingStop::Phase::kWrite && (pace == StopPace::kNow || stop.due <= now)) {
      ids.push_back(id);
    }
  }
  std::vector<bool> written;
  lock.unlock();
  client_.writeStops(ids, &written);
  lock.lock();
  const core::Clock::time_point after = clock_.now();
  std::vector<std::pair<uint8_t, ServoStatus>> failures;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    auto it = stops_.find(ids[i]);
    if (it == stops_.end() || it->second.phase != PendingStop::Phase::kWrite) continue;
    PendingStop& stop = it->second;
    stop.port_down = !written[i];
    if (!written[i]) {
      stop.at_rest = false;  // pending again until it went out and the servo was seen at rest
      stop.due = after + kStopRetry;
      stop.why = "not written: the servo bus port is down";
      failures.push_back({ids[i], {ServoError::kNotConnected, stop.why}});
      continue;
    }
    ++stop.written;
    on_written_locked_(ids[i]);
    if (ids[i] == kBroadcastId) {
      stops_.erase(it);  // nothing answers a broadcast: written is all that can be known
      continue;
    }
    if (stop.at_rest) {
      stop.due = after + kStopRepeat;  // seen at rest already: written again while the e-stop holds
      continue;
    }
    stop.phase = PendingStop::Phase::kFirstLook;
    stop.due = after;
    stop.why = "written, not yet seen at rest";
  }
  // A stop armed meanwhile keeps the bus reserved; otherwise the callers may go on.
  const bool more = std::any_of(stops_.begin(), stops_.end(), [&](const auto& entry) {
    return entry.second.phase == PendingStop::Phase::kWrite && entry.second.due <= after;
  });
  if (!more || pace == StopPace::kNow) endUrgentLocked();
  lock.unlock();
  for (const auto& [id, status] : failures) {
    if (events_.on_stop) events_.on_stop(id, status);
  }
  lock.lock();
}

ServoStatus StopKeeper::seenAtRestLocked(std::map<uint8_t, PendingStop>::iterator it,
                                         double angle_deg, core::Clock::time_point now) {
  PendingStop& stop = it->second;
  char text[96];
  std::snprintf(text, sizeof(text), "at rest at %.1f deg after %d stop(s)", angle_deg,
                stop.written);
  const ServoStatus outcome{ServoError::kOk, text};
  if (!stop.repeat) {
    stops_.erase(it);
    return outcome;
  }
  // Rest and a slow motion look alike here: the e-stop's stop goes out again until released.
  stop.at_rest = true;
  stop.phase = PendingStop::Phase::kWrite;
  stop.due = now + kStopRepeat;
  stop.why = outcome.message + "; written again every " + std::to_string(kStopRepeat.count()) +
             " ms while the e-stop holds";
  return outcome;
}

void StopKeeper::lookAtStoppedServo(std::unique_lock<std::mutex>& lock, uint8_t id, StopPace pace) {
  const PendingStop::Phase phase = stops_.at(id).phase;
  lock.unlock();
  // Paced by the bus's clock, the second look is due kStopSettle after the first; back to back
  // (shutdown), the settle is slept here.
  if (pace == StopPace::kNow && phase == PendingStop::Phase::kSecondLook) {
    std::this_thread::sleep_for(kStopSettle);
  }
  double angle_deg = 0.0;
  const BusPriority priority =
      pace == StopPace::kScheduled ? BusPriority::kWorker : BusPriority::kCaller;
  const ServoStatus read = client_.readAngle(id, &angle_deg, nullptr, priority);
  lock.lock();
  if (read.error == ServoError::kPreempted) return;  // a stop to write went first: look again
  auto it = stops_.find(id);
  if (it == stops_.end() || it->second.phase != phase) return;  // released or re-armed meanwhile
  PendingStop& stop = it->second;
  const core::Clock::time_point now = clock_.now();
  ServoStatus outcome;
  if (!read.ok()) {
    stop.phase = PendingStop::Phase::kWrite;
    stop.due = now + stopBackoff(stop.written);
    stop.why = "no answer after the stop (" + read.message + ")";
    outcome = {read.error, stop.why};
  } else if (phase == PendingStop::Phase::kFirstLook) {
    stop.first_angle = angle_deg;
    stop.phase = PendingStop::Phase::kSecondLook;
    stop.due = now + kStopSettle;
    return;
  } else if (std::fabs(angle_deg - stop.first_angle) > kRestToleranceDeg) {
    char text[96];
    std::snprintf(text, sizeof(text), "still moving after the stop (%.1f deg in %lld ms)",
                  angle_deg - stop.first_angle, static_cast<long long>(kStopSettle.count()));
    stop.phase = PendingStop::Phase::kWrite;
    stop.due = now;
    stop.why = text;
    outcome = {ServoError::kMotionRefused, text};
  } else {
    outcome = seenAtRestLocked(it, angle_deg, now);
  }
  const bool rewrite = !outcome.ok() && outcome.error != ServoError::kTimeout &&
                       outcome.error != ServoError::kNotConnected;
  lock.unlock();
  if (rewrite && pace == StopPace::kScheduled) askUrgent();  // still moving: again, first
  if (events_.on_stop) events_.on_stop(id, outcome);
  lock.lock();
}

}  // namespace serial_robot_driver::devices::servo_bus
