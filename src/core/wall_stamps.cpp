#include "serial_robot_driver/core/wall_stamps.h"

#include <algorithm>

namespace serial_robot_driver::core {

std::chrono::nanoseconds wallTimeOf(std::chrono::steady_clock::time_point event,
                                    std::chrono::system_clock::time_point wall_now,
                                    std::chrono::steady_clock::time_point steady_now) {
  const auto age = std::max(std::chrono::nanoseconds(0), steady_now - event);
  const auto wall =
      std::chrono::duration_cast<std::chrono::nanoseconds>(wall_now.time_since_epoch());
  return std::max(std::chrono::nanoseconds(0), wall - age);
}

std::chrono::nanoseconds WallStamps::operator()(
    std::chrono::steady_clock::time_point arrival) const {
  if (replay_timeline_) {
    return std::max(std::chrono::nanoseconds(0), replay_timeline_->recordedAt(arrival));
  }
  thread_local std::chrono::steady_clock::time_point last_arrival{};
  thread_local std::chrono::nanoseconds last_stamp{0};
  if (arrival != last_arrival || last_stamp.count() == 0) {
    // Both clocks back to back, so the offset between them is as exact as it can be.
    const auto steady_now = std::chrono::steady_clock::now();
    last_stamp = wallTimeOf(arrival, std::chrono::system_clock::now(), steady_now);
    last_arrival = arrival;
  }
  return last_stamp;
}

}  // namespace serial_robot_driver::core
