#include "serial_robot_driver/devices/echo/echo_controller.h"

#include "serial_robot_driver/devices/echo/echo_codec.h"

namespace serial_robot_driver::devices::echo {

EchoController::EchoController(core::FrameWriter writer, std::chrono::milliseconds timeout)
    : writer_(std::move(writer)), timeout_(timeout) {}

PingResult EchoController::ping() {
  std::lock_guard<std::mutex> one_at_a_time(ping_mutex_);
  std::vector<uint8_t> payload;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // The sequence number makes each payload unique, so a late answer cannot pass for this one.
    const uint32_t sequence = ++sequence_;
    payload = {static_cast<uint8_t>(sequence >> 24),
               static_cast<uint8_t>(sequence >> 16),
               static_cast<uint8_t>(sequence >> 8),
               static_cast<uint8_t>(sequence),
               'e',
               'c',
               'h',
               'o'};
    expected_ = payload;
    answer_arrival_.reset();
    ++stats_.pings;
  }
  const core::Clock::time_point sent = core::Clock::now();
  if (!writer_(encodeRequest(payload))) {
    std::lock_guard<std::mutex> lock(mutex_);
    expected_.reset();
    ++stats_.write_failures;
    stats_.last_ping_failed = true;
    return PingResult{false, {}, "the port is down"};
  }
  std::unique_lock<std::mutex> lock(mutex_);
  const bool answered =
      answered_.wait_for(lock, timeout_, [this] { return answer_arrival_.has_value(); });
  expected_.reset();
  stats_.last_ping_failed = !answered;
  if (!answered) {
    ++stats_.timeouts;
    return PingResult{false, {}, "no answer within " + std::to_string(timeout_.count()) + " ms"};
  }
  const auto round_trip = std::max(core::Clock::duration::zero(), *answer_arrival_ - sent);
  stats_.last_round_trip = round_trip;
  return PingResult{true, round_trip, ""};
}

void EchoController::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                             core::Clock::time_point arrival) {
  if (family != kAnswerFrames) return;
  const auto payload = decode(kAnswerType, data, size);
  std::lock_guard<std::mutex> lock(mutex_);
  if (!payload || !expected_ || *payload != *expected_ || answer_arrival_) {
    ++stats_.mismatches;
    return;
  }
  answer_arrival_ = arrival;
  ++stats_.round_trips;
  answered_.notify_all();
}

EchoStats EchoController::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace serial_robot_driver::devices::echo
