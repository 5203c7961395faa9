#include "serial_robot_driver/device/servo_bus.h"

#include <algorithm>
#include <utility>

namespace serial_robot_driver::device {

namespace {
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
  wake_.notify_all();
}

void ServoBus::dropQueuedMoves(uint8_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
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
  wake_.notify_all();  // the worker may be waiting for a poll that is now due earlier
}

void ServoBus::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (started_ || stop_) return;
  started_ = true;
  worker_ = std::thread([this] { workerLoop(); });
}

void ServoBus::shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  // The worker's poll is one background transaction at most.
  if (worker_.joinable()) worker_.join();
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

void ServoBus::workerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    if (!queued_moves_.empty()) {
      const MoveRequest move = queued_moves_.front();
      queued_moves_.pop_front();
      lock.unlock();
      sendMove(move);
      lock.lock();
      continue;
    }
    // The servo whose poll is due first.
    auto due = std::min_element(
        polled_.begin(), polled_.end(),
        [](const PolledServo& a, const PolledServo& b) { return a.next_poll < b.next_poll; });
    if (due == polled_.end()) {
      wake_.wait(lock, [this] { return stop_ || !queued_moves_.empty(); });
      continue;
    }
    // Health polls are background work of a second kind, due at their own (lower) rate.
    const Clock::time_point health_due = nextHealthPoll();
    if (health_due <= clock_->now()) {
      const auto first = std::min_element(
          health_.begin(), health_.end(),
          [](const HealthServo& a, const HealthServo& b) { return a.next_poll < b.next_poll; });
      const auto index = static_cast<std::size_t>(first - health_.begin());
      lock.unlock();
      pollHealthOnce(index);
      lock.lock();
      continue;
    }
    if (clock_->now() < due->next_poll) {
      clock_->waitUntil(lock, wake_, std::min(due->next_poll, health_due));
      continue;
    }
    PolledServo& servo = *due;
    lock.unlock();
    pollOnce(servo);  // the schedule is only changed by this thread; mutex_ for stats() readers
    lock.lock();
  }
}

void ServoBus::sendMove(const MoveRequest& move) {
  ServoStatus status = refuseWhileLocked(move.id);  // an overheated servo (protect)
  if (status.ok()) status = client_.move(move);
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
  const Clock::time_point now = clock_->now();
  bool went_silent = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status.error == ServoError::kNotConnected || status.error == ServoError::kShutdown) {
      // The port is down, not the servo: ask again at the poll rate once it is back.
      servo.next_poll = now + poll_period_;
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
