#include "serial_robot_driver/devices/base/base_controller.h"

#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "serial_robot_driver/core/clock.h"
#include "serial_robot_driver/core/guarded_call.h"
#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/core/scheduler_slice.h"

namespace serial_robot_driver::devices::base {

using kinematics::WheelSpeeds;

namespace {

/// A speed frame's airtime at `baud` (start + 8 data + stop bits per byte), stretched so that
/// frames sent this closely take at most `line_share` of the line.
core::Clock::duration immediateInterval(int baud, double line_share) {
  const double frame_bits = 10.0 * static_cast<double>(encodeWheelSpeed(0, 0, 0).size());
  const double airtime = frame_bits / std::max(baud, 1);
  return core::fromSeconds(airtime / std::clamp(line_share, 0.01, 1.0));
}

int16_t withDirection(int16_t ticks, int direction) {
  if (direction >= 0) return ticks;
  // -(-32768) does not fit in int16: saturate.
  return ticks == std::numeric_limits<int16_t>::min() ? std::numeric_limits<int16_t>::max()
                                                      : static_cast<int16_t>(-ticks);
}

}  // namespace

BaseController::BaseController(BaseConfig config, core::FrameWriter writer, BaseEvents events,
                               std::shared_ptr<core::LoopClock> clock)
    : config_(config),
      writer_(std::move(writer)),
      events_(std::move(events)),
      clock_(clock ? std::move(clock) : core::steadyLoopClock()),
      period_(core::fromSeconds(1.0 / config.loop_rate)),
      min_immediate_interval_(immediateInterval(config.baud, config.immediate_line_share)),
      limiter_(config.max_wheel_accel),
      quantizer_(config.geometry, config.speed_dithering),
      odometry_(config) {}

BaseController::~BaseController() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify();
  if (loop_.joinable()) loop_.join();
}

CommandOutcome BaseController::submitCommand(double linear_x, double angular_z,
                                             std::optional<Generation> accepted) {
  const bool valid = std::isfinite(linear_x) && std::isfinite(angular_z);
  SpeedFrameReport report;
  bool written_here = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (e_stop_) {
      ++stats_.ignored_commands_e_stop;
      return CommandOutcome::kEStopEngaged;
    }
    if (accepted && *accepted != generation_) {
      ++stats_.voided_commands;
      return CommandOutcome::kVoided;
    }
    linear_x_ = valid ? linear_x : 0.0;
    angular_z_ = valid ? angular_z : 0.0;
    const core::Clock::time_point now = clock_->now();
    last_command_ = now;
    if (!valid) ++stats_.rejected_commands;
    // Written here and now, on the caller's thread, under the lock every base write takes: the
    // e-stop, the deadman, the limits, the ramp and the sequence are decided at the moment of
    // writing, and the loop's next tick goes on from this frame. A flood beyond the line's share
    // (or a command before start()) is left to the loop, which writes it as soon as it may.
    written_here = valid && mayRushLocked(now);
    if (written_here) {
      command_pending_ = false;  // this frame carries whatever was pending
      sendSpeedLocked(now, true, &report);
    } else {
      command_pending_ = true;
    }
  }
  if (!written_here) {
    wake_.notify();
    return valid ? CommandOutcome::kStored : CommandOutcome::kNotFinite;
  }
  reportSpeedFrame(report);
  return CommandOutcome::kSent;
}

bool BaseController::mayRushLocked(core::Clock::time_point now) const {
  return running_ && lineAllowsImmediateLocked(now);
}

bool BaseController::lineAllowsImmediateLocked(core::Clock::time_point now) const {
  // The 50 Hz ticks are not counted against the line's share: they are a small, fixed load, and
  // counting them would hold back every command that follows a tick.
  return !last_immediate_frame_ || now - *last_immediate_frame_ >= min_immediate_interval_;
}

BaseController::Generation BaseController::generation() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return generation_;
}

void BaseController::setEStop(bool engaged) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (engaged == e_stop_) return;
    e_stop_ = engaged;
    stats_.e_stop = engaged;
    if (engaged) {
      ++generation_;
      command_pending_ = true;  // the zero frame goes out now, not at the next tick
    }
    // Dropped on the engagement (and again on the release): only a cmd_vel accepted after the
    // release drives the base.
    last_command_.reset();
    linear_x_ = angular_z_ = 0.0;
  }
  wake_.notify();
}

bool BaseController::commandMovesLocked(core::Clock::time_point now) const {
  const bool command_live =
      !e_stop_ && last_command_ && core::toSeconds(now - *last_command_) <= config_.cmd_vel_timeout;
  return command_live && (linear_x_ != 0.0 || angular_z_ != 0.0);
}

bool BaseController::rampingLocked() const { return !e_stop_ && !limiter_.current().isZero(0.0); }

bool BaseController::inMotion() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return commandMovesLocked(clock_->now()) || rampingLocked();
}

std::string BaseController::motionInForce() const {
  std::lock_guard<std::mutex> lock(mutex_);
  char text[128];
  if (commandMovesLocked(clock_->now())) {
    std::snprintf(text, sizeof text, "cmd_vel of %.3g m/s, %.3g rad/s in force", linear_x_,
                  angular_z_);
    return text;
  }
  if (rampingLocked()) {
    const WheelSpeeds& ramp = limiter_.current();
    std::snprintf(text, sizeof text, "wheels still ramping (%.3g, %.3g m/s)", ramp.x(), ramp.y());
    return text;
  }
  return {};
}

void BaseController::resetOdometry() {
  std::lock_guard<std::mutex> lock(mutex_);
  odometry_.reset(clock_->now());
}

void BaseController::onImuYaw(double yaw, core::Clock::time_point stamp) {
  // Not under mutex_: the odometry takes the sample under the heading fusion's own short lock.
  odometry_.addImuYaw(yaw, stamp);
}

void BaseController::setImuYawVariance(double variance) {
  std::lock_guard<std::mutex> lock(mutex_);
  odometry_.setImuYawVariance(variance);
}

bool BaseController::sendReset() {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::Clock::time_point now = clock_->now();
  const bool ok = writeLocked(encodeReset(seq_.peek()), now);
  if (ok) {
    ++stats_.resets_sent;
    needs_reset_ = false;
    last_reset_sent_ = now;
  }
  return ok;
}

bool BaseController::sendClearEncoders() {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool ok = writeLocked(encodeClearEncoders(seq_.peek()), clock_->now());
  if (ok) ++stats_.clear_encoders_sent;
  return ok;
}

void BaseController::start() {
  if (loop_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = !stopping_;  // from now on a cmd_vel is written by its caller, at once
  }
  // Not tunable: read before the thread runs.
  const int priority = config_.realtime_priority;
  const int slice_us = config_.scheduler_slice_us;
  loop_ = std::thread([this, priority, slice_us] {
    ::pthread_setname_np(::pthread_self(), "srd_base_loop");  // as ps -L, top -H and perf show it
    // The slice first: a thread already at SCHED_FIFO takes none. Either refused, the loop runs
    // all the same at the normal policy.
    core::requestSchedulerSlice(slice_us);
    core::enterRealtime(priority);
    run();
  });
}

void BaseController::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stopped_) return;
    stopping_ = true;
    stopped_ = true;
    running_ = false;  // no cmd_vel written after the last words below
  }
  wake_.notify();
  if (loop_.joinable()) loop_.join();
  // Last words: a zero-speed frame, so the wheels stop now rather than at the base's 1 s timeout.
  WheelFrameSent sent;
  bool written = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sent.seq = seq_.peek();
    sent.time = clock_->now();
    written = writeLocked(encodeWheelSpeed(sent.seq, 0, 0), sent.time);
    if (written) {
      ++stats_.speed_frames;
      if (!needs_reset_) odometry_.speedAccepted(kinematics::WheelTicks{}, sent.time);
      unreported_frames_.push_back(sent);
    }
  }
  reportWrittenFrames();
}

void BaseController::retune(const BaseTuning& next) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::Clock::time_point now = clock_->now();
  // The motion so far with the geometry it ran under, from now on with the new one.
  odometry_.retune(next.geometry, next.use_imu_heading, now);
  limiter_.setMaxAccel(next.max_wheel_accel);
  quantizer_.retune(next.geometry, next.speed_dithering);
  rescheduleBatteryPollLocked(next.battery_poll_rate, now);
  static_cast<BaseTuning&>(config_) = next;
}

void BaseController::rescheduleBatteryPollLocked(double next_rate, core::Clock::time_point now) {
  if (next_rate == config_.battery_poll_rate) return;
  if (next_rate > 0) {
    // A faster rate starts now, not after the slower period still pending.
    next_battery_poll_ = std::min(next_battery_poll_, now + core::fromSeconds(1.0 / next_rate));
  } else {
    unanswered_since_.reset();  // no requests, nothing unanswered
    silent_reported_ = false;
  }
}

BaseConfig BaseController::config() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return config_;
}

BaseStats BaseController::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::Clock::time_point now = clock_->now();
  BaseStats snapshot = stats_;
  odometry_.addHeadingStats(snapshot, now);
  snapshot.min_immediate_interval_ms = core::toSeconds(min_immediate_interval_) * 1e3;
  if (last_running_timeout_error_) {
    snapshot.seconds_since_running_timeout_error =
        core::toSeconds(now - *last_running_timeout_error_);
  }
  if (config_.battery_poll_rate > 0 && unanswered_since_) {
    snapshot.seconds_without_reply = core::toSeconds(now - *unanswered_since_);
    snapshot.base_silent =
        *snapshot.seconds_without_reply > config_.silent_after_polls / config_.battery_poll_rate;
  }
  return snapshot;
}

void BaseController::onLinkUp() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    needs_reset_ = true;  // the base may have timed out while we were away
    quantizer_.reset();
    command_pending_ = true;
    unanswered_since_.reset();  // a new connection gets its own poll periods to answer
    silent_reported_ = false;
  }
  wake_.notify();
}

void BaseController::onLinkDown() {
  std::lock_guard<std::mutex> lock(mutex_);
  needs_reset_ = true;
}

void BaseController::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                             core::Clock::time_point arrival) {
  if (family != kFrames) return;
  const auto frame = decodeFrame(data, size);
  if (!frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.bad_replies;
    return;
  }
  const auto reply = interpretReply(*frame);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!reply) {
      ++stats_.bad_replies;
      return;
    }
    unanswered_since_.reset();  // any well-formed frame shows the base is there
    silent_reported_ = false;
  }
  switch (reply->kind) {
    case Reply::Kind::kTimeoutError: {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        const core::Clock::time_point now = clock_->now();
        ++stats_.timeout_errors_received;
        // One FF may still be in flight from before our Reset (e.g. at power-on): not "running".
        const bool running = !needs_reset_ && last_reset_sent_ &&
                             core::toSeconds(now - *last_reset_sent_) >= config_.heartbeat_gap;
        if (running) {
          ++stats_.timeout_errors_while_running;
          last_running_timeout_error_ = now;
        }
        // The base has stopped its wheels and ignores speed frames until our next Reset.
        odometry_.baseStopped(now);
        needs_reset_ = true;
        command_pending_ = true;  // Reset on the wire now, not at the next tick
      }
      wake_.notify();
      if (events_.on_timeout_error) events_.on_timeout_error();
      break;
    }
    case Reply::Kind::kBattery: {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.battery_replies;
        stats_.battery_percent = reply->battery_percent;
      }
      if (events_.on_battery) events_.on_battery(reply->battery_percent, arrival);
      break;
    }
    case Reply::Kind::kUnknown: {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.unknown_replies;
      }
      if (events_.on_unknown_reply) events_.on_unknown_reply(reply->frame);
      break;
    }
  }
}

bool BaseController::writeLocked(const std::vector<uint8_t>& frame, core::Clock::time_point now) {
  if (!writer_(frame)) {
    ++stats_.write_failures;
    needs_reset_ = true;  // whatever the base saw, start the next exchange with a Reset
    return false;
  }
  seq_.next();
  last_write_ = now;
  return true;
}

WheelSpeeds BaseController::targetSpeedsLocked(core::Clock::time_point now, bool* timed_out_now) {
  if (e_stop_) return WheelSpeeds::Zero();
  const bool timed_out =
      !last_command_ || core::toSeconds(now - *last_command_) > config_.cmd_vel_timeout;
  if (timed_out && !command_timed_out_ && last_command_) {
    ++stats_.cmd_vel_timeouts;
    *timed_out_now = true;
  }
  command_timed_out_ = timed_out;
  if (timed_out) return WheelSpeeds::Zero();
  // Work on the twist scaled to at most 1 so absurd (finite) commands cannot overflow to inf and
  // lose their direction; the clamp then restores the right magnitude.
  const double scale = std::max({1.0, std::abs(linear_x_), std::abs(angular_z_)});
  const WheelSpeeds unit =
      kinematics::wheelSpeedsFromTwist(config_.geometry, linear_x_ / scale, angular_z_ / scale);
  return kinematics::clampWheelSpeeds(unit, config_.max_wheel_speed / scale) * scale;
}

kinematics::WheelTicks BaseController::onWire(const kinematics::WheelTicks& ticks) const {
  return kinematics::WheelTicks{withDirection(ticks.left, config_.left_wheel_direction),
                                withDirection(ticks.right, config_.right_wheel_direction)};
}

void BaseController::sendSpeed(core::Clock::time_point now, bool immediate) {
  SpeedFrameReport report;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sendSpeedLocked(now, immediate, &report);
  }
  reportSpeedFrame(report);
}

void BaseController::sendSpeedLocked(core::Clock::time_point now, bool immediate,
                                     SpeedFrameReport* report) {
  // A tick that read the clock before a cmd_vel's frame took the lock goes on from that frame:
  // frame times (and so the ramp's steps and the odometry's intervals) never run backwards.
  if (last_write_ && now < *last_write_) now = *last_write_;
  const double dt =
      last_speed_frame_ ? core::toSeconds(now - *last_speed_frame_) : core::toSeconds(period_);
  const WheelSpeeds target = targetSpeedsLocked(now, &report->timed_out_now);
  if (e_stop_) {
    limiter_.reset();  // an e-stop does not ramp down
    quantizer_.reset();
  }
  const WheelSpeeds speeds = e_stop_ ? target : limiter_.step(target, dt);

  // The base drops into its timeout error after 1 s without a frame; if our own gap reached that,
  // assume it did, even if its FF frame was lost.
  if (last_write_ && core::toSeconds(now - *last_write_) >= config_.heartbeat_gap)
    needs_reset_ = true;
  WheelFrameSent sent;
  if (needs_reset_) {
    if (!writeLocked(encodeReset(seq_.peek()), now)) return;
    ++stats_.resets_sent;
    needs_reset_ = false;
    last_reset_sent_ = now;
    sent.reset_before = true;
  }
  const kinematics::WheelTicks ticks = quantizer_.quantize(speeds);
  sent.ticks = onWire(ticks);
  sent.seq = seq_.peek();
  sent.speeds = speeds;
  sent.time = now;
  if (!writeLocked(encodeWheelSpeed(sent.seq, sent.ticks.left, sent.ticks.right), now)) return;
  ++stats_.speed_frames;
  if (immediate) {
    ++stats_.immediate_frames;
    last_immediate_frame_ = now;
  }
  last_speed_frame_ = now;
  odometry_.speedAccepted(ticks, now);  // a Reset went out before it whenever one was due
  report->sent = sent;
  unreported_frames_.push_back(sent);
}

void BaseController::reportSpeedFrame(const SpeedFrameReport& report) {
  if (report.timed_out_now && events_.on_cmd_vel_timeout) events_.on_cmd_vel_timeout();
  if (report.sent) reportWrittenFrames();
}

void BaseController::reportWrittenFrames() {
  std::lock_guard<std::mutex> reporting(report_mutex_);
  while (true) {
    WheelFrameSent sent;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (unreported_frames_.empty()) return;
      sent = unreported_frames_.front();
      unreported_frames_.pop_front();
    }
    if (events_.on_wheel_frame) events_.on_wheel_frame(sent);
  }
}

void BaseController::tick(core::Clock::time_point now) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (last_tick_) {
      const double period_ms = core::toSeconds(now - *last_tick_) * 1e3;
      stats_.last_period_ms = period_ms;
      if (period_ms > stats_.worst_period_ms) stats_.worst_period_ms = period_ms;
    }
    last_tick_ = now;
    if (config_.battery_poll_rate > 0 && now >= next_battery_poll_) {
      next_battery_poll_ =
          now + std::chrono::duration_cast<core::Clock::duration>(
                    std::chrono::duration<double>(1.0 / config_.battery_poll_rate));
      // A Reset pending goes out with the speed frame below; the battery request can wait for it.
      if (!needs_reset_ && writeLocked(encodeBatteryRequest(seq_.peek()), now)) {
        ++stats_.battery_requests;
        if (!unanswered_since_) unanswered_since_ = now;
      }
    }
  }
  sendSpeed(now, false);

  std::optional<double> went_silent;
  std::optional<kinematics::HeadingSource> heading_changed;
  OdometrySample sample;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (config_.battery_poll_rate > 0 && unanswered_since_ && !silent_reported_) {
      const double silent_for = core::toSeconds(now - *unanswered_since_);
      if (silent_for > config_.silent_after_polls / config_.battery_poll_rate) {
        silent_reported_ = true;
        went_silent = silent_for;
      }
    }
    odometry_.advance(now);
    sample = odometry_.sample(now);
    heading_changed = odometry_.headingSourceChange();
  }
  if (went_silent && events_.on_silent) events_.on_silent(*went_silent);
  if (heading_changed && events_.on_heading_source) events_.on_heading_source(*heading_changed);
  if (events_.on_odometry) events_.on_odometry(sample);
}

template <typename Step>
void BaseController::guarded(const Step& step) {
  // The loop's last line: what a step lets out (a bug here or in an output) loses that step only,
  // so the heartbeat and the e-stop's zero frames keep going out.
  core::catchAll(step, [this](const std::string& what) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.internal_errors;
      stats_.last_internal_error = what;
    }
    if (internal_error_log_.pass()) {
      core::log(core::LogLevel::kError, "base loop: internal error, this tick was cut short: %s",
                what.c_str());
    }
  });
}

void BaseController::run() {
  core::Clock::time_point deadline = clock_->now() + period_;
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    // Wake at the next tick, or earlier for a new command that may be rushed out.
    while (!stopping_ && !command_pending_ && clock_->now() < deadline) {
      clock_->waitUntil(lock, wake_, deadline);
    }
    if (stopping_) break;
    const core::Clock::time_point now = clock_->now();
    if (now < deadline) {
      // Woken early (an e-stop, an FF error, a link up, or a cmd_vel its caller could not write
      // yet): send it at once unless the last rushed frame is so recent that a flood would take
      // more than its share of the line; then it goes when the line allows (or with the tick).
      if (!lineAllowsImmediateLocked(now)) {
        const core::Clock::time_point until =
            std::min(deadline, *last_immediate_frame_ + min_immediate_interval_);
        while (!stopping_ && clock_->now() < until) clock_->waitUntil(lock, wake_, until);
        continue;  // re-evaluate with command_pending_ still set
      }
      command_pending_ = false;
      lock.unlock();
      guarded([&] { sendSpeed(now, true); });
      lock.lock();
      continue;
    }
    command_pending_ = false;
    lock.unlock();
    guarded([&] { tick(now); });
    lock.lock();
    deadline += period_;
    if (clock_->now() >= deadline) {
      // Late by a whole period (machine stalled): count it and re-anchor rather than burst.
      ++stats_.loop_overruns;
      deadline = clock_->now() + period_;
    }
  }
}

}  // namespace serial_robot_driver::devices::base
