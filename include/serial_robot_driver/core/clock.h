// The clock every device and the simulator time their frames by, and its conversions to and from
// the seconds that parameters and kinematics are given in.
#pragma once

#include <chrono>

namespace serial_robot_driver::core {

using Clock = std::chrono::steady_clock;

/// Seconds as a double, for rates and kinematics.
inline double toSeconds(Clock::duration duration) {
  return std::chrono::duration<double>(duration).count();
}

/// A duration from (possibly fractional) seconds.
inline Clock::duration fromSeconds(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace serial_robot_driver::core
