// What the node refused of the inputs that reach it (topics, services, action goals), by source:
// messages and requests that failed their checks, and callbacks that ended in an unexpected error
// (caught at the edge, logged and answered as a failure, never let into roscpp). The node reports
// them in its "e_stop" status next to the commands the e-stop refused. ROS-free; any thread.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

struct InputRefusalStats {
  std::map<std::string, uint64_t> refused;  ///< inputs that failed their checks, by source
  std::map<std::string, uint64_t> errors;   ///< callbacks ended by an unexpected error, by source

  /// Adds `other`'s counts (the node sums its devices' and its own).
  InputRefusalStats& operator+=(const InputRefusalStats& other);
};

class InputRefusals {
 public:
  /// An input from `source` (e.g. "joint_trajectory", "servo/move") failed its checks.
  void refused(const std::string& source);
  /// A callback of `source` ended in an unexpected error.
  void failed(const std::string& source);
  InputRefusalStats stats() const;

 private:
  mutable std::mutex mutex_;  // guards stats_
  InputRefusalStats stats_;
};

/// Adds "inputs refused: <source>" per source and their total "inputs refused", then
/// "callback errors: <source>" and "callback errors" to `status`. The level is left as it is:
/// a refused input is the sender's mistake, and each callback error is logged.
void addInputRefusals(const InputRefusalStats& stats, StatusReport& status);

}  // namespace serial_robot_driver::core
