#include "serial_robot_driver/core/loop_wake.h"

#include <cerrno>
#include <chrono>
#include <ctime>

namespace serial_robot_driver::core {

LoopWake::LoopWake() { ::sem_init(&semaphore_, 0, 0); }

LoopWake::~LoopWake() { ::sem_destroy(&semaphore_); }

void LoopWake::notify() {
  // At most one pending post (or a few, from notifiers racing): a worker that is not running yet
  // must not collect one per command.
  int pending = 0;
  ::sem_getvalue(&semaphore_, &pending);
  if (pending <= 0) ::sem_post(&semaphore_);
}

void LoopWake::dropPending() {
  while (::sem_trywait(&semaphore_) == 0) {
  }
}

bool LoopWake::waitUntil(std::unique_lock<std::mutex>& lock, Clock::time_point deadline) {
  // steady_clock is CLOCK_MONOTONIC: its time since epoch is that clock's reading.
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(deadline.time_since_epoch()).count();
  const timespec until{static_cast<time_t>(ns / 1000000000),
                       static_cast<long>(ns % 1000000000)};  // NOLINT: timespec's type
  dropPending();
  lock.unlock();
  int result = 0;
  do {
    result = ::sem_clockwait(&semaphore_, CLOCK_MONOTONIC, &until);
  } while (result != 0 && errno == EINTR);
  lock.lock();
  return result == 0;
}

}  // namespace serial_robot_driver::core
