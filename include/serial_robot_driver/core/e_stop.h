// The robot's one emergency stop, shared by every device: the node owns one EStop and hands it to
// each device's interface, which registers what engaging and releasing it means for that device
// (the base holds zero speed, trajectories abort, spinning bus servos get a SPIN stop) and asks
// it before obeying a motion command. ROS-free.
//
// Threading model: listeners are registered before set() is first called (at construction of the
// node); set() may then be called from any thread and runs the listeners on that thread, in
// registration order, serialized by set_mutex_ so an engage and a release never interleave.
// engaged() and refuse() are lock-free reads plus a counter under state_mutex_.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace serial_robot_driver::core {

struct EStopStats {
  bool engaged = false;
  uint64_t engagements = 0;                 ///< false -> true transitions
  std::map<std::string, uint64_t> refused;  ///< motion commands refused while engaged, by source
};

class EStop {
 public:
  /// Called with the new state on every change (not on a repeated message of the same state).
  using Listener = std::function<void(bool engaged)>;

  /// Before the first set().
  void addListener(Listener listener);
  /// Engages or releases; runs the listeners when the state changes. Returns whether it changed.
  bool set(bool engaged);
  bool engaged() const { return engaged_.load(); }
  /// A motion command from `source` (e.g. "cmd_vel", "servo/spin") asks to move: when the e-stop is
  /// engaged it is counted as refused and true is returned (the caller must not obey it).
  bool refuse(const std::string& source);

  EStopStats stats() const;

 private:
  std::vector<Listener> listeners_;
  std::mutex set_mutex_;  // one change at a time, listeners included
  std::atomic<bool> engaged_{false};
  mutable std::mutex state_mutex_;  // guards stats_
  EStopStats stats_;
};

}  // namespace serial_robot_driver::core
