#include "serial_robot_driver/devices/base/sim/base_sim.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::devices::base::sim {

using serial_robot_driver::sim::fromSeconds;
using serial_robot_driver::sim::Outbox;
using serial_robot_driver::sim::Outgoing;
using serial_robot_driver::sim::OutputKind;
using serial_robot_driver::sim::TimePoint;

const OutputKind kBaseReplyOutput{"base_replies", 1};

BaseSim::BaseSim(const BaseSimConfig& config, TimePoint now)
    : config_(config),
      pid_period_(fromSeconds(1.0 / std::max(config.pid_rate_hz, 1e-3))),
      next_pid_(now + pid_period_),
      last_host_frame_(now),  // the heartbeat runs from power-on, like the real base
      next_error_frame_(now) {}

void BaseSim::emit(Outbox* out, std::vector<uint8_t> frame) {
  out->push_back(Outgoing{&kBaseReplyOutput, std::move(frame)});
}

void BaseSim::handleFrame(const uint8_t* data, std::size_t size, TimePoint now, Outbox* out) {
  const auto decoded = decodeFrame(data, size);
  if (!decoded) {
    ++stats_.unknown_frames;
    return;
  }
  const Frame& frame = *decoded;
  ++stats_.frames_received;
  last_host_frame_ = now;
  if (have_seq_ && frame.seq != expected_seq_) ++stats_.seq_gaps;
  have_seq_ = true;
  expected_seq_ = static_cast<uint8_t>(frame.seq + 1);

  switch (static_cast<MsgId>(frame.msg_id)) {
    case MsgId::kWheelSpeed: {
      const auto speed = interpretWheelSpeed(frame);
      if (!speed) {
        ++stats_.unknown_frames;
        break;
      }
      if (stats_.in_error) {
        ++stats_.speed_frames_ignored;
        break;
      }
      const int16_t limit = config_.max_ticks_per_period;
      stats_.last_left_speed = std::clamp<int16_t>(speed->left_ticks, -limit, limit);
      stats_.last_right_speed = std::clamp<int16_t>(speed->right_ticks, -limit, limit);
      ++stats_.speed_frames_applied;
      break;
    }
    case MsgId::kBattery:
      ++stats_.battery_requests;
      emit(out, encodeBatteryReply(reply_seq_.next(), config_.battery_percent));
      break;
    case MsgId::kReset:
      ++stats_.resets;
      stats_.in_error = false;
      break;
    case MsgId::kClearEncoders:
      ++stats_.encoder_clears;
      stats_.left_ticks = 0;
      stats_.right_ticks = 0;
      break;
    default:
      ++stats_.unknown_frames;
      break;
  }
}

void BaseSim::enterError(TimePoint now, Outbox* out) {
  stats_.in_error = true;
  ++stats_.timeouts;
  // A base that lost its host stops rather than running on the last command.
  stats_.last_left_speed = 0;
  stats_.last_right_speed = 0;
  emit(out, encodeErrorStatus(reply_seq_.next()));
  ++stats_.errors_sent;
  next_error_frame_ = now + fromSeconds(config_.error_repeat_s);
}

void BaseSim::tick(TimePoint now, Outbox* out) {
  // After a long stall (debugger, suspended process) skip the missed periods instead of looping.
  if (now - next_pid_ > std::chrono::seconds(1)) next_pid_ = now;
  while (next_pid_ <= now) {
    stats_.left_ticks += stats_.last_left_speed;
    stats_.right_ticks += stats_.last_right_speed;
    advancePose();
    next_pid_ += pid_period_;
  }

  if (!stats_.in_error) {
    if (now - last_host_frame_ > fromSeconds(config_.heartbeat_timeout_s)) enterError(now, out);
  } else if (now >= next_error_frame_) {
    emit(out, encodeErrorStatus(reply_seq_.next()));
    ++stats_.errors_sent;
    next_error_frame_ += fromSeconds(config_.error_repeat_s);
    if (next_error_frame_ <= now) next_error_frame_ = now + fromSeconds(config_.error_repeat_s);
  }
}

TimePoint BaseSim::nextEvent() const {
  TimePoint next = next_pid_;
  if (stats_.in_error) {
    next = std::min(next, next_error_frame_);
  } else {
    // One tick just past the deadline: the timeout is "more than" heartbeat_timeout_s.
    next = std::min(next, last_host_frame_ + fromSeconds(config_.heartbeat_timeout_s) +
                              std::chrono::milliseconds(1));
  }
  return next;
}

void BaseSim::advancePose() {
  const double meters_per_tick = config_.wheel_diameter_m * M_PI / config_.encoder_resolution;
  const double left = stats_.last_left_speed * meters_per_tick;
  const double right = stats_.last_right_speed * meters_per_tick;
  const double forward = (left + right) / 2.0;
  const double turn = (right - left) / config_.wheel_separation_m * (1.0 - config_.turn_slip);
  const double heading = stats_.yaw_rad + turn / 2.0;
  stats_.x_m += forward * std::cos(heading);
  stats_.y_m += forward * std::sin(heading);
  stats_.yaw_rad = std::remainder(stats_.yaw_rad + turn, 2.0 * M_PI);
}

double BaseSim::yawRate() const {
  const double ticks_per_meter = config_.encoder_resolution / (config_.wheel_diameter_m * M_PI);
  const double to_mps = config_.pid_rate_hz / ticks_per_meter;
  const double left = stats_.last_left_speed * to_mps;
  const double right = stats_.last_right_speed * to_mps;
  return (right - left) / config_.wheel_separation_m * (1.0 - config_.turn_slip);
}

}  // namespace serial_robot_driver::devices::base::sim
