// The clock a device's worker thread reads and waits on. Production uses the steady clock; tests
// pass a clock they move themselves (test/support/manual_clock.h), so schedules are tested
// without sleeping.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>

#include "serial_robot_driver/core/loop_wake.h"
#include "serial_robot_driver/core/serial_link.h"

namespace serial_robot_driver::core {

class LoopClock {
 public:
  virtual ~LoopClock() = default;
  virtual Clock::time_point now() const = 0;
  /// Called by a worker with `lock` (the device's mutex) held: waits on `wake` until `deadline` on
  /// this clock or a notification, whichever comes first. May return early; the worker checks
  /// again.
  virtual void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& wake,
                         Clock::time_point deadline) = 0;
  /// The same for a worker woken through a LoopWake (see there: notifications pending while
  /// `lock` is held are dropped).
  virtual void waitUntil(std::unique_lock<std::mutex>& lock, LoopWake& wake,
                         Clock::time_point deadline) = 0;
};

/// The steady clock (Clock) as a LoopClock.
std::shared_ptr<LoopClock> steadyLoopClock();

}  // namespace serial_robot_driver::core
