// What ends a worker thread's timed wait early: a command, an e-stop, a link event, stop(). A
// POSIX semaphore, so that a periodic loop waits in one system call per period as a
// clock_nanosleep would: a condition variable's timed wait takes two (its timeout ends with a
// futex wake-up too), about 4 us more per tick on a 2-core VM (bench/bench_wait.cpp).
#pragma once

#include <semaphore.h>

#include <mutex>

#include "serial_robot_driver/core/serial_link.h"

namespace serial_robot_driver::core {

/// The worker's state lives under its own mutex; a thread that changes it (under that mutex) then
/// calls notify(). The worker checks its state under the mutex and, when nothing is due, calls
/// waitUntil() with the mutex still held: notifications pending then are for what it has just
/// seen and are dropped, so one change never ends two waits.
class LoopWake {
 public:
  LoopWake();
  ~LoopWake();
  LoopWake(const LoopWake&) = delete;
  LoopWake& operator=(const LoopWake&) = delete;

  /// Ends the worker's wait, or its next one if it is not waiting yet. Any thread, any lock held
  /// or none; never blocks.
  void notify();

  /// With `lock` (the worker's mutex) held: drops the notifications seen, releases the mutex,
  /// waits until `deadline` (steady clock; Clock::time_point::max() for a notify() alone, as a
  /// test's manual clock waits) or a notify(), and takes the mutex again. True when a notify()
  /// ended it.
  bool waitUntil(std::unique_lock<std::mutex>& lock, Clock::time_point deadline);

 private:
  void dropPending();
  sem_t semaphore_;
};

}  // namespace serial_robot_driver::core
