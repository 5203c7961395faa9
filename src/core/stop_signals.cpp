#include "serial_robot_driver/core/stop_signals.h"

#include <pthread.h>

#include <algorithm>
#include <ctime>

namespace serial_robot_driver::core {

StopSignals::StopSignals() {
  sigemptyset(&signals_);
  sigaddset(&signals_, SIGINT);
  sigaddset(&signals_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
}

bool StopSignals::wait(std::chrono::milliseconds period, const std::function<bool()>& running,
                       const std::function<bool()>& done) const {
  period = std::max(period, std::chrono::milliseconds(0));  // a negative timeout is invalid
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(period);
  const timespec timeout{static_cast<time_t>(seconds.count()),
                         static_cast<long>(std::chrono::nanoseconds(period - seconds).count())};
  while (!running || running()) {
    if (done && done()) return true;
    if (sigtimedwait(&signals_, nullptr, &timeout) > 0) return false;
  }
  return false;
}

}  // namespace serial_robot_driver::core
