// The ServoBus's stops: the e-stop's lock, stopServo() and the last words at shutdown. A stop is
// kept until its servo is known to have it: written (as urgent work on the bus), then the servo
// seen at rest by two angle reads kStopSettle apart. A stop that could not be written, after which
// the servo did not answer, or that left it moving is written again; every reconnect writes the
// e-stop's stops again first.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

#include "serial_robot_driver/device/servo_bus.h"
#include "servo_bus_text.h"

namespace serial_robot_driver::device {

namespace {

/// A stop that could not be written is tried again after this; a reconnect tries it at once.
constexpr std::chrono::milliseconds kStopRetry{100};
/// A servo silent after its stop is asked again after a back-off doubling up to this.
constexpr std::chrono::milliseconds kLongestStopBackoff{2000};

std::chrono::milliseconds stopBackoff(int written) {
  const int doublings = std::clamp(written - 1, 0, 5);
  return std::min(kStopRetry * (1 << doublings), kLongestStopBackoff);
}

}  // namespace

std::optional<ShutdownAction> shutdownActionFromString(const std::string& text) {
  if (text == "stop") return ShutdownAction::kStop;
  if (text == "relax") return ShutdownAction::kRelax;
  if (text == "none") return ShutdownAction::kNone;
  return std::nullopt;
}

const char* toString(ShutdownAction action) {
  switch (action) {
    case ShutdownAction::kStop:
      return "stop";
    case ShutdownAction::kRelax:
      return "relax";
    case ShutdownAction::kNone:
      return "none";
  }
  return "?";
}

void ServoBus::armStopLocked(uint8_t id, Clock::time_point now) {
  PendingStop& stop = stops_[id];
  stop.phase = PendingStop::Phase::kWrite;
  stop.due = now;
}

void ServoBus::setMotionLocked(bool locked) {
  // First the gate: from its return on no motion frame is written, whoever is waiting to.
  gate_.setLocked(locked);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    motion_locked_ = locked;
    if (!locked) {
      stops_.clear();  // released: nothing is to be held back any more
      endUrgentLocked();
      return;
    }
    queued_moves_.clear();
    const Clock::time_point now = clock_->now();
    for (uint8_t id : commanded_) armStopLocked(id, now);
    if (stops_.empty()) return;
  }
  deliverStops();
}

void ServoBus::stopServo(uint8_t id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    dropQueuedMovesLocked(id);
    armStopLocked(id, clock_->now());
  }
  deliverStops();
}

void ServoBus::deliverStops() {
  bool worker_running = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    worker_running = started_ && !stop_;
  }
  if (worker_running) {
    askUrgent();  // nobody takes the bus before the worker has written them
    wakeWorker();
    return;
  }
  // No worker (before start()): write them here; their confirmation waits for the worker.
  std::unique_lock<std::mutex> lock(mutex_);
  writeDueStops(lock, StopPace::kNow);
}

void ServoBus::onLinkUp() {
  // On the reader thread, before any write on the reopened port can succeed: the stops go first.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const Clock::time_point now = clock_->now();
    if (motion_locked_) {
      for (uint8_t id : commanded_) armStopLocked(id, now);
    }
    for (auto& [id, stop] : stops_) armStopLocked(id, now);
    if (stops_.empty() || !started_ || stop_) return;
  }
  askUrgent();
  wakeWorker();  // a worker of its own; on the link, this thread is the worker
}

void ServoBus::askUrgent() {
  // Under mutex_, so the flag and the client's reservation change together.
  std::lock_guard<std::mutex> lock(mutex_);
  urgent_asked_ = true;
  client_.requestUrgent();
}

void ServoBus::endUrgentLocked() {
  if (!std::exchange(urgent_asked_, false)) return;
  client_.endUrgent();  // takes only the client's own locks
}

Clock::time_point ServoBus::nextStopWork() const {
  // The bus is reserved for stops (askUrgent): the worker must see to it now, even when the stop
  // it was asked for is gone meanwhile (released, superseded), or every caller would wait.
  if (urgent_asked_) return Clock::time_point::min();
  Clock::time_point next = Clock::time_point::max();
  for (const auto& [id, stop] : stops_) next = std::min(next, stop.due);
  return next;
}

std::vector<PendingStopReport> ServoBus::pendingStops() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<PendingStopReport> reports;
  for (const auto& [id, stop] : stops_) reports.push_back({id, stop.written, stop.why});
  return reports;
}

bool ServoBus::stopWorkOnce(std::unique_lock<std::mutex>& lock, StopPace pace) {
  const Clock::time_point now = clock_->now();
  const auto due = [&](const PendingStop& stop) {
    return pace == StopPace::kNow || stop.due <= now;
  };
  for (const auto& [id, stop] : stops_) {
    if (stop.phase == PendingStop::Phase::kWrite && due(stop)) {
      writeDueStops(lock, pace);
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

void ServoBus::writeDueStops(std::unique_lock<std::mutex>& lock, StopPace pace) {
  std::vector<uint8_t> ids;
  const Clock::time_point now = clock_->now();
  for (const auto& [id, stop] : stops_) {
    if (stop.phase == PendingStop::Phase::kWrite && (pace == StopPace::kNow || stop.due <= now)) {
      ids.push_back(id);
    }
  }
  std::vector<bool> written;
  lock.unlock();
  client_.writeStops(ids, &written);
  lock.lock();
  const Clock::time_point after = clock_->now();
  std::vector<std::pair<uint8_t, ServoStatus>> failures;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    auto it = stops_.find(ids[i]);
    if (it == stops_.end() || it->second.phase != PendingStop::Phase::kWrite) continue;
    PendingStop& stop = it->second;
    stop.port_down = !written[i];
    if (!written[i]) {
      stop.due = after + kStopRetry;
      stop.why = "not written: the servo bus port is down";
      failures.push_back({ids[i], {ServoError::kNotConnected, stop.why}});
      continue;
    }
    ++stop.written;
    if (ids[i] == protocol::servo::kBroadcastId) moving_.clear();
    moving_.erase(ids[i]);
    if (ids[i] == protocol::servo::kBroadcastId) {
      stops_.erase(it);  // nothing answers a broadcast: written is all that can be known
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

void ServoBus::lookAtStoppedServo(std::unique_lock<std::mutex>& lock, uint8_t id, StopPace pace) {
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
  const Clock::time_point now = clock_->now();
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
    char text[96];
    std::snprintf(text, sizeof(text), "at rest at %.1f deg after %d stop(s)", angle_deg,
                  stop.written);
    outcome = {ServoError::kOk, text};
    stops_.erase(it);
  }
  const bool rewrite = !outcome.ok() && outcome.error != ServoError::kTimeout &&
                       outcome.error != ServoError::kNotConnected;
  lock.unlock();
  if (rewrite && pace == StopPace::kScheduled) askUrgent();  // still moving: again, first
  if (events_.on_stop) events_.on_stop(id, outcome);
  lock.lock();
}

void ServoBus::finalWords() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (final_words_said_) return;
    final_words_said_ = true;
  }
  const ServoBusConfig in_force = settings();
  const auto deadline = std::chrono::steady_clock::now() + kShutdownStopBudget;
  std::unique_lock<std::mutex> lock(mutex_);
  switch (in_force.on_shutdown) {
    case ShutdownAction::kStop: {
      const Clock::time_point now = clock_->now();
      for (uint8_t id : commanded_) armStopLocked(id, now);
      // Back to back on this thread (the worker has stopped), until each is seen at rest.
      while (!stops_.empty() && std::chrono::steady_clock::now() < deadline) {
        const bool port_down = std::all_of(
            stops_.begin(), stops_.end(), [](const auto& entry) { return entry.second.port_down; });
        if (port_down) {  // a port that is down has nothing to gain from a busy loop
          lock.unlock();
          std::this_thread::sleep_for(kStopRetry);
          lock.lock();
        }
        stopWorkOnce(lock, StopPace::kNow);
      }
      break;
    }
    case ShutdownAction::kRelax: {
      const std::vector<uint8_t> ids(commanded_.begin(), commanded_.end());
      lock.unlock();
      for (uint8_t id : ids) {
        // A write that failed (port down) is tried again until the budget is spent.
        while (
            !client_.damping(id, in_force.relax_power_mw, false, FrameGate::kSafetyAction).ok() &&
            std::chrono::steady_clock::now() < deadline) {
          std::this_thread::sleep_for(kStopRetry);
        }
      }
      lock.lock();
      break;
    }
    case ShutdownAction::kNone:
      break;
  }
  std::vector<std::pair<uint8_t, std::string>> unconfirmed;
  for (const auto& [id, stop] : stops_) unconfirmed.push_back({id, stop.why});
  endUrgentLocked();  // the callers still waiting get the bus (and kShutdown)
  lock.unlock();
  for (const auto& [id, why] : unconfirmed) {
    if (events_.on_stop) {
      events_.on_stop(id, {ServoError::kShutdown, servo_text::servoName(id) +
                                                      "'s stop not confirmed at shutdown: " + why});
    }
  }
}

}  // namespace serial_robot_driver::device
