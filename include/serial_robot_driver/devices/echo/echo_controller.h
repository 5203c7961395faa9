// The echo device's logic, ROS-free: ping() writes a request carrying a fresh sequence number and
// waits for the answer with the same payload; the link's reader thread hands answers in
// (onFrame). Counts round trips, answers that match no request in flight, and timeouts.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"

namespace serial_robot_driver::devices::echo {

struct EchoStats {
  uint64_t pings = 0;        ///< requests written
  uint64_t round_trips = 0;  ///< answers matching the request in flight
  uint64_t mismatches = 0;   ///< answers with another payload (late, or damaged), or undecodable
  uint64_t timeouts = 0;     ///< no matching answer in time
  uint64_t write_failures = 0;
  std::optional<std::chrono::nanoseconds> last_round_trip;  ///< of the last successful ping
  bool last_ping_failed = false;                            ///< no answer, or not sent
};

struct PingResult {
  bool ok = false;
  std::chrono::nanoseconds round_trip{0};
  std::string error;  ///< why not, when !ok
};

class EchoController : public core::LinkListener {
 public:
  EchoController(core::FrameWriter writer, std::chrono::milliseconds timeout);

  /// Writes one request and waits up to the timeout for its answer. Call from any thread but the
  /// link's reader (which delivers the answer); one ping at a time, others wait their turn.
  PingResult ping();

  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               core::Clock::time_point arrival) override;

  EchoStats stats() const;

 private:
  core::FrameWriter writer_;
  const std::chrono::milliseconds timeout_;
  std::mutex ping_mutex_;     ///< one ping in flight
  mutable std::mutex mutex_;  ///< guards what follows
  std::condition_variable answered_;
  std::optional<std::vector<uint8_t>> expected_;  ///< the payload in flight
  std::optional<core::Clock::time_point> answer_arrival_;
  uint32_t sequence_ = 0;
  EchoStats stats_;
};

}  // namespace serial_robot_driver::devices::echo
