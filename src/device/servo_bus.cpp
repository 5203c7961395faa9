#include "serial_robot_driver/device/servo_bus.h"

#include <algorithm>
#include <utility>

namespace serial_robot_driver::device {

namespace {
/// How often a polled servo is asked again while its port is down (reopened every
/// reconnect_interval, 1 s by default).
constexpr std::chrono::milliseconds kPortDownRetry{100};

Clock::duration periodOf(double rate_hz) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
}
}  // namespace

ServoBus::ServoBus(ServoBusConfig config, FrameWriter writer, ServoBusEvents events,
                   std::shared_ptr<LoopClock> clock)
    : config_(std::move(config)),
      settings_(config_),
      events_(std::move(events)),
      clock_(clock ? std::move(clock) : steadyLoopClock()),
      poll_period_(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / config_.poll_rate))),
      client_(config_.client, std::move(writer)) {
  client_.setMotionGate(&gate_, [this](uint8_t id) { noteCommanded(id); });
  const Clock::time_point now = clock_->now();
  for (uint8_t id : config_.polled_ids) {
    PolledServo servo;
    servo.id = id;
    servo.next_poll = now;
    polled_.push_back(servo);
  }
  // Every polled servo has a health entry, so a health_rate turned on at runtime finds them.
  if (config_.health_rate > 0.0) health_period_ = periodOf(config_.health_rate);
  for (uint8_t id : config_.polled_ids) {
    HealthServo servo;
    servo.report.id = id;
    servo.next_poll = now;
    health_.push_back(servo);
  }
}

ServoBus::~ServoBus() { shutdown(); }

void ServoBus::onLinkDown() { client_.onLinkDown(); }

void ServoBus::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                       Clock::time_point arrival) {
  client_.onFrame(family, data, size, arrival);
}

void ServoBus::queueMoves(const std::vector<MoveRequest>& moves) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (motion_locked_) return;  // the e-stop holds: the caller refused (and counted) it already
    for (const MoveRequest& move : moves) {
      auto queued = std::find_if(queued_moves_.begin(), queued_moves_.end(),
                                 [&move](const MoveRequest& m) { return m.id == move.id; });
      if (queued != queued_moves_.end()) {
        *queued = move;
        ++stats_.moves_replaced;
      } else {
        queued_moves_.push_back(move);
      }
    }
  }
  wakeWorker();
}

void ServoBus::dropQueuedMoves(uint8_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  dropQueuedMovesLocked(id);
}

void ServoBus::dropQueuedMovesLocked(uint8_t id) {
  queued_moves_.erase(std::remove_if(queued_moves_.begin(), queued_moves_.end(),
                                     [id](const MoveRequest& m) { return m.id == id; }),
                      queued_moves_.end());
}

void ServoBus::retune(const ServoBusConfig& next) {
  client_.retune(next.client.timeout, next.client.retries);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    settings_.client.timeout = next.client.timeout;
    settings_.client.retries = next.client.retries;
    settings_.poll_rate = next.poll_rate;
    settings_.health_rate = next.health_rate;
    settings_.relax_power_mw = next.relax_power_mw;
    settings_.protect = next.protect;
    settings_.on_shutdown = next.on_shutdown;
    poll_period_ = periodOf(next.poll_rate);
    const Clock::time_point now = clock_->now();
    const Clock::time_point soonest = now + poll_period_;
    for (PolledServo& servo : polled_) {
      // A servo in back-off keeps its back-off; the others are due within the new period.
      if (servo.backoff.count() == 0) servo.next_poll = std::min(servo.next_poll, soonest);
    }
    const bool health_was_off = health_period_.count() == 0;
    health_period_ = next.health_rate > 0.0 ? periodOf(next.health_rate) : Clock::duration(0);
    for (HealthServo& servo : health_) {
      servo.next_poll = health_was_off ? now : std::min(servo.next_poll, now + health_period_);
    }
  }
  wakeWorker();  // the worker may be waiting for a poll that is now due earlier
}

void ServoBus::start() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (started_ || stop_) return;
    started_ = true;
    if (link_ == nullptr) worker_ = std::thread([this] { workerLoop(); });
  }
  if (link_ != nullptr) link_->wake();  // the reader thread takes the work from now on
}

void ServoBus::shutdown() {
  // The last words are decided from here on: no motion frame passes any more, whoever waited.
  gate_.close();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wakeWorker();
  // The worker's poll is one background transaction at most.
  if (worker_.joinable()) worker_.join();
  {
    // Running on the link's reader thread: the piece of work in progress ends first.
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait(lock, [this] { return !working_; });
  }
  finalWords();
  client_.shutdown();  // every later call fails at once
}

ServoBusConfig ServoBus::settings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return settings_;
}

ServoBusWorkerStats ServoBus::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  ServoBusWorkerStats stats = stats_;
  for (const PolledServo& servo : polled_) {
    if (servo.backoff.count() > 0) stats.offline_ids.push_back(servo.id);
  }
  const double poll_rate = 1.0 / std::chrono::duration<double>(poll_period_).count();
  stats.asked_poll_rate =
      poll_rate * static_cast<double>(polled_.size() - stats.offline_ids.size());
  return stats;
}

void ServoBus::runOn(SerialLink& link) {
  link_ = &link;
  link.addListener(this);
  link.setWorker(this);
  client_.setReaderPump({[&link] { return link.onReaderThread(); },
                         [&link](Clock::time_point until) { return link.pump(until); },
                         [&link] { link.wake(); }});
}

void ServoBus::wakeWorker() {
  wake_.notify_all();
  if (link_ != nullptr) link_->wake();
}

Clock::time_point ServoBus::nextWorkLocked() const {
  if (!started_ || stop_) return Clock::time_point::max();
  if (!queued_moves_.empty()) return Clock::time_point::min();
  Clock::time_point next = std::min(nextStopWork(), nextHealthPoll());
  for (const PolledServo& servo : polled_) next = std::min(next, servo.next_poll);
  return next;
}

Clock::time_point ServoBus::nextWork() {
  std::lock_guard<std::mutex> lock(mutex_);
  return nextWorkLocked();
}

void ServoBus::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!started_ || stop_) return;
  working_ = true;
  workOnce(lock);
  working_ = false;
  lock.unlock();
  wake_.notify_all();  // shutdown() waits for the piece of work in progress
}

void ServoBus::workerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    Clock::time_point due = nextWorkLocked();
    // Nothing scheduled: wait to be woken (bounded, so the clock's arithmetic cannot overflow).
    if (due == Clock::time_point::max()) due = clock_->now() + std::chrono::hours(1);
    if (clock_->now() < due) {
      clock_->waitUntil(lock, wake_, due);
    } else {
      workOnce(lock);
    }
  }
}

void ServoBus::workOnce(std::unique_lock<std::mutex>& lock) {
  // Stops first: nothing else this bus does may go before them.
  if (stopWorkOnce(lock, StopPace::kScheduled)) return;
  if (!queued_moves_.empty()) {
    const MoveRequest move = queued_moves_.front();
    queued_moves_.pop_front();
    lock.unlock();
    sendMove(move);
    lock.lock();
    return;
  }
  const Clock::time_point now = clock_->now();
  // Health polls are background work of a second kind, due at their own (lower) rate.
  if (nextHealthPoll() <= now) {
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
  pollOnce(servo);  // the schedule is only changed by this thread; mutex_ for stats() readers
  lock.lock();
}

void ServoBus::sendMove(const MoveRequest& move) {
  ServoStatus status = refuseWhileLocked(move.id);  // an overheated servo (protect)
  if (status.ok()) {
    // Through the motion gate: refused if the e-stop came meanwhile.
    status = client_.move(move, BusPriority::kWorker);
  }
  if (status.error == ServoError::kPreempted) {
    // A stop goes first; the move goes after it unless a newer target or the e-stop replaced it.
    std::lock_guard<std::mutex> lock(mutex_);
    const bool replaced = std::any_of(queued_moves_.begin(), queued_moves_.end(),
                                      [&move](const MoveRequest& m) { return m.id == move.id; });
    if (!replaced && !motion_locked_ && stops_.count(move.id) == 0) queued_moves_.push_front(move);
    return;
  }
  if (status.ok()) noteMotion(move.id, true);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status.ok()) {
      ++stats_.moves_sent;
    } else {
      ++stats_.moves_failed;
    }
  }
  if (!status.ok() && events_.on_move_failed) events_.on_move_failed(move, status);
}

void ServoBus::pollOnce(PolledServo& servo) {
  ServoAngleSample sample;
  sample.id = servo.id;
  const ServoStatus status =
      client_.readAngle(servo.id, &sample.angle_deg, &sample.arrival, BusPriority::kBackground);
  if (status.error == ServoError::kPreempted) return;  // a stop went first: due again at once
  const Clock::time_point now = clock_->now();
  bool went_silent = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status.error == ServoError::kNotConnected || status.error == ServoError::kShutdown) {
      // The port is down, not the servo: ask again at the poll rate, but no more often than
      // kPortDownRetry, so a down port at a high state_rate does not keep the worker busy.
      servo.next_poll = now + std::max<Clock::duration>(poll_period_, kPortDownRetry);
      return;
    }
    if (!status.ok()) {
      went_silent = servo.backoff.count() == 0;
      servo.backoff = went_silent ? kFirstBackoff : std::min(servo.backoff * 2, kMaxBackoff);
      servo.next_poll = now + servo.backoff;
    } else {
      servo.backoff = std::chrono::milliseconds(0);
      // Keep the rate without drifting; after a stall, start again from now.
      servo.next_poll = std::max(servo.next_poll + poll_period_, now);
      ++stats_.angles_polled;
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

}  // namespace serial_robot_driver::device
