// The core's log: lines that the devices' and the ports' events produce (a cmd_vel timeout, a
// silent base, a port lost) are written here once, whichever front ends run. A front end sets the
// sink once, before the devices start (the ROS node: ROS_DEBUG .. ROS_ERROR); without one, INFO and
// above go to stderr. ROS-free; any thread.
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

namespace serial_robot_driver::core {

enum class LogLevel { kDebug, kInfo, kWarn, kError };

/// Receives every line the core logs, on the thread whose event caused it.
using LogSink = std::function<void(LogLevel level, const std::string& text)>;

/// Replaces the sink (empty: stderr again). Before the devices start; not while they log.
void setLogSink(LogSink sink);

/// Formats (printf) and writes one line to the sink.
void log(LogLevel level, const char* format, ...) __attribute__((format(printf, 2, 3)));

/// Lets a repeated event through at most once per period (ROS_*_THROTTLE's rule): one per kind of
/// line, owned by what logs it. Any thread.
class LogThrottle {
 public:
  explicit LogThrottle(double period_s) : period_(period_s) {}
  /// Whether to log now; true the first time, then once the period has passed since the last true.
  bool pass();

 private:
  const std::chrono::duration<double> period_;
  std::mutex mutex_;  // guards last_
  std::optional<std::chrono::steady_clock::time_point> last_;
};

}  // namespace serial_robot_driver::core
