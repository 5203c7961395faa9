#include "serial_robot_driver/device/base_controller.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::device {

namespace base = protocol::base;
using kinematics::WheelSpeeds;

namespace {
double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

class SteadyLoopClock : public LoopClock {
 public:
  Clock::time_point now() const override { return Clock::now(); }
  void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& wake,
                 Clock::time_point deadline) override {
    wake.wait_until(lock, deadline);
  }
};
}  // namespace

BaseController::BaseController(BaseConfig config, FrameWriter writer, BaseEvents events,
                               std::shared_ptr<LoopClock> clock)
    : config_(config),
      writer_(std::move(writer)),
      events_(std::move(events)),
      clock_(clock ? std::move(clock) : std::make_shared<SteadyLoopClock>()),
      period_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / config.loop_rate))),
      limiter_(config.max_wheel_accel),
      quantizer_(config.geometry, config.speed_dithering) {}

BaseController::~BaseController() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (loop_.joinable()) loop_.join();
}

bool BaseController::setCommand(double linear_x, double angular_z) {
  const bool valid = std::isfinite(linear_x) && std::isfinite(angular_z);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    linear_x_ = valid ? linear_x : 0.0;
    angular_z_ = valid ? angular_z : 0.0;
    last_command_ = clock_->now();
    command_pending_ = true;
    if (!valid) ++stats_.rejected_commands;
  }
  wake_.notify_all();
  return valid;
}

bool BaseController::sendReset() {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool ok = writeLocked(base::encodeReset(seq_.peek()), clock_->now());
  if (ok) {
    ++stats_.resets_sent;
    needs_reset_ = false;
  }
  return ok;
}

bool BaseController::sendClearEncoders() {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool ok = writeLocked(base::encodeClearEncoders(seq_.peek()), clock_->now());
  if (ok) ++stats_.clear_encoders_sent;
  return ok;
}

void BaseController::start() {
  if (loop_.joinable()) return;
  loop_ = std::thread([this] { run(); });
}

void BaseController::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return;
    stopping_ = true;
    stopped_ = true;
  }
  wake_.notify_all();
  if (loop_.joinable()) loop_.join();
  // Last words: a zero-speed frame, so the wheels stop now rather than at the base's 1 s timeout.
  WheelFrameSent sent;
  bool written = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sent.seq = seq_.peek();
    sent.time = clock_->now();
    written = writeLocked(base::encodeWheelSpeed(sent.seq, 0, 0), sent.time);
    if (written) ++stats_.speed_frames;
  }
  if (written && events_.on_wheel_frame) events_.on_wheel_frame(sent);
}

BaseStats BaseController::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void BaseController::onLinkUp() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    needs_reset_ = true;  // the base may have timed out while we were away
    quantizer_.reset();
    command_pending_ = true;
  }
  wake_.notify_all();
}

void BaseController::onLinkDown() {
  std::lock_guard<std::mutex> lock(mutex_);
  needs_reset_ = true;
}

void BaseController::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                             Clock::time_point arrival) {
  if (family != protocol::FrameFamily::kBase) return;
  const auto frame = base::decodeFrame(data, size);
  if (!frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.bad_replies;
    return;
  }
  const auto reply = base::interpretReply(*frame);
  if (!reply) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.bad_replies;
    return;
  }
  switch (reply->kind) {
    case base::Reply::Kind::kTimeoutError: {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.timeout_errors_received;
        needs_reset_ = true;
        command_pending_ = true;  // Reset on the wire now, not at the next tick
      }
      wake_.notify_all();
      if (events_.on_timeout_error) events_.on_timeout_error();
      break;
    }
    case base::Reply::Kind::kBattery: {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.battery_replies;
        stats_.battery_percent = reply->battery_percent;
      }
      if (events_.on_battery) events_.on_battery(reply->battery_percent, arrival);
      break;
    }
    case base::Reply::Kind::kUnknown: {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.unknown_replies;
      }
      if (events_.on_unknown_reply) events_.on_unknown_reply(reply->frame);
      break;
    }
  }
}

bool BaseController::writeLocked(const std::vector<uint8_t>& frame, Clock::time_point now) {
  if (!writer_(frame)) {
    ++stats_.write_failures;
    needs_reset_ = true;  // whatever the base saw, start the next exchange with a Reset
    return false;
  }
  seq_.next();
  last_write_ = now;
  return true;
}

WheelSpeeds BaseController::targetSpeedsLocked(Clock::time_point now) {
  const bool timed_out =
      !last_command_ || seconds(now - *last_command_) > config_.cmd_vel_timeout;
  if (timed_out && !command_timed_out_ && last_command_) ++stats_.cmd_vel_timeouts;
  command_timed_out_ = timed_out;
  if (timed_out) return WheelSpeeds::Zero();
  // Work on the twist scaled to at most 1 so absurd (finite) commands cannot overflow to inf and
  // lose their direction; the clamp then restores the right magnitude.
  const double scale = std::max({1.0, std::abs(linear_x_), std::abs(angular_z_)});
  const WheelSpeeds unit =
      kinematics::wheelSpeedsFromTwist(config_.geometry, linear_x_ / scale, angular_z_ / scale);
  const double largest = unit.cwiseAbs().maxCoeff();
  if (config_.max_wheel_speed > 0 && largest * scale > config_.max_wheel_speed) {
    return unit * (config_.max_wheel_speed / largest);
  }
  return unit * scale;
}

void BaseController::sendSpeed(Clock::time_point now, bool immediate) {
  WheelFrameSent sent;
  bool written = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const double dt = last_speed_frame_ ? seconds(now - *last_speed_frame_) : seconds(period_);
    const WheelSpeeds speeds = limiter_.step(targetSpeedsLocked(now), dt);

    // The base drops into its timeout error after 1 s without a frame; if our own gap reached that,
    // assume it did, even if its FF frame was lost.
    if (last_write_ && seconds(now - *last_write_) >= config_.heartbeat_gap) needs_reset_ = true;
    if (needs_reset_) {
      if (!writeLocked(base::encodeReset(seq_.peek()), now)) return;
      ++stats_.resets_sent;
      needs_reset_ = false;
      sent.reset_before = true;
    }
    sent.ticks = quantizer_.quantize(speeds);
    sent.seq = seq_.peek();
    sent.speeds = speeds;
    sent.time = now;
    written = writeLocked(base::encodeWheelSpeed(sent.seq, sent.ticks.left, sent.ticks.right), now);
    if (written) {
      ++stats_.speed_frames;
      if (immediate) ++stats_.immediate_frames;
      last_speed_frame_ = now;
    }
  }
  if (written && events_.on_wheel_frame) events_.on_wheel_frame(sent);
}

void BaseController::tick(Clock::time_point now) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (last_tick_) {
      const double period_ms = seconds(now - *last_tick_) * 1e3;
      stats_.last_period_ms = period_ms;
      if (period_ms > stats_.worst_period_ms) stats_.worst_period_ms = period_ms;
    }
    last_tick_ = now;
    if (config_.battery_poll_rate > 0 && now >= next_battery_poll_) {
      next_battery_poll_ = now + std::chrono::duration_cast<Clock::duration>(
                                     std::chrono::duration<double>(1.0 / config_.battery_poll_rate));
      // A Reset pending goes out with the speed frame below; the battery request can wait for it.
      if (!needs_reset_ && writeLocked(base::encodeBatteryRequest(seq_.peek()), now)) {
        ++stats_.battery_requests;
      }
    }
  }
  sendSpeed(now, false);
}

void BaseController::run() {
  Clock::time_point deadline = clock_->now() + period_;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    // Wake at the next tick, or earlier for a new command that may be rushed out.
    while (!stopping_ && !command_pending_ && clock_->now() < deadline) {
      clock_->waitUntil(lock, wake_, deadline);
    }
    if (stopping_) break;
    const Clock::time_point now = clock_->now();
    if (now < deadline) {
      // Woken early by a command: send it at once unless the last frame is too recent; then it
      // waits for the tick, which is at most one period away.
      const bool may_rush = !last_speed_frame_ || (now - *last_speed_frame_) * 2 >= period_;
      if (!may_rush) {
        const Clock::time_point until = std::min(deadline, *last_speed_frame_ + period_ / 2);
        while (!stopping_ && clock_->now() < until) clock_->waitUntil(lock, wake_, until);
        continue;  // re-evaluate with command_pending_ still set
      }
      command_pending_ = false;
      lock.unlock();
      sendSpeed(now, true);
      lock.lock();
      continue;
    }
    command_pending_ = false;
    lock.unlock();
    tick(now);
    lock.lock();
    deadline += period_;
    if (clock_->now() >= deadline) {
      // Late by a whole period (machine stalled): count it and re-anchor rather than burst.
      ++stats_.loop_overruns;
      deadline = clock_->now() + period_;
    }
  }
}

}  // namespace serial_robot_driver::device
