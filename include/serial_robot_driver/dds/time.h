#pragma once
// builtin_interfaces/Time and Duration from and to nanoseconds (ROS 2's split: sec may be negative,
// nanosec always in [0, 1e9)).

#include <cstdint>

#include "builtin_interfaces/msg/Duration.h"
#include "builtin_interfaces/msg/Time.h"

namespace serial_robot_driver {
namespace dds {

namespace time_detail {
constexpr int64_t kNanosecondsPerSecond = 1000000000;
// Floor division, so that -1 ns is {-1 s, 999999999 ns} as in rclcpp.
inline void split(int64_t nanoseconds, int32_t& sec, uint32_t& nanosec) {
  int64_t seconds = nanoseconds / kNanosecondsPerSecond;
  int64_t rest = nanoseconds % kNanosecondsPerSecond;
  if (rest < 0) {
    rest += kNanosecondsPerSecond;
    --seconds;
  }
  sec = static_cast<int32_t>(seconds);
  nanosec = static_cast<uint32_t>(rest);
}
}  // namespace time_detail

inline builtin_interfaces_msg_dds__Time_ timeFromNanoseconds(int64_t nanoseconds) {
  builtin_interfaces_msg_dds__Time_ time{};
  time_detail::split(nanoseconds, time.sec, time.nanosec);
  return time;
}

inline builtin_interfaces_msg_dds__Duration_ durationFromNanoseconds(int64_t nanoseconds) {
  builtin_interfaces_msg_dds__Duration_ duration{};
  time_detail::split(nanoseconds, duration.sec, duration.nanosec);
  return duration;
}

/// Works for Time and Duration.
template <typename TimeOrDuration>
int64_t toNanoseconds(const TimeOrDuration& value) {
  return static_cast<int64_t>(value.sec) * time_detail::kNanosecondsPerSecond + value.nanosec;
}

}  // namespace dds
}  // namespace serial_robot_driver
