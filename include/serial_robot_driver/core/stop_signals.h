// SIGINT and SIGTERM taken synchronously, for the driver's and the simulator's processes: blocked
// in the constructing thread, and so in every thread started after it (construct it before any
// thread starts), then waited for with sigtimedwait(). No handler runs at an arbitrary point: the
// process stops its own way (the driver writes its last zero-speed frame first).
#pragma once

#include <signal.h>

#include <chrono>
#include <functional>

namespace serial_robot_driver::core {

class StopSignals {
 public:
  /// Blocks SIGINT and SIGTERM in the calling thread (and the threads it starts from now on).
  StopSignals();

  /// Waits for a stop signal, for `running` (empty: always) to turn false or for `done` (empty:
  /// never) to hold, checking them every `period`. Returns true when `done` ended the wait.
  bool wait(std::chrono::milliseconds period, const std::function<bool()>& running = {},
            const std::function<bool()>& done = {}) const;

 private:
  sigset_t signals_;
};

}  // namespace serial_robot_driver::core
