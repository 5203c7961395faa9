// A LoopClock that tests move themselves (shared by the BaseController and ServoBus tests).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>

#include "serial_robot_driver/core/loop_clock.h"

namespace serial_robot_driver::core {

/// A LoopClock the test moves: the controller's loop thread runs for real, but its time only
/// passes when the test says so, and each step returns once the loop has done what fell due.
class ManualClock : public LoopClock {
 public:
  explicit ManualClock(Clock::time_point start) : now_(start) {}

  Clock::time_point now() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    return now_;
  }

  void waitUntil(std::unique_lock<std::mutex>& loop_lock, std::condition_variable& wake,
                 Clock::time_point /*deadline*/) override {
    enterWait(loop_lock, [&wake] { wake.notify_all(); });
    wake.wait(loop_lock);  // until advance() or the controller itself notifies
    leaveWait();
  }

  void waitUntil(std::unique_lock<std::mutex>& loop_lock, LoopWake& wake,
                 Clock::time_point /*deadline*/) override {
    enterWait(loop_lock, [&wake] { wake.notify(); });
    // Until advance() or the controller itself notifies.
    wake.waitUntil(loop_lock, Clock::time_point::max());
    leaveWait();
  }

  /// Returns once the loop thread waits for the first time (call after start()).
  void waitForLoop() { settleAfter(0); }

  /// Runs `action` (something that wakes the loop, e.g. a new command) and returns once the loop
  /// has handled it and waits again.
  template <typename Action>
  void step(Action action) {
    const uint64_t seen = waits();
    action();
    settleAfter(seen);
  }

  /// As step(), for an action that may not wake the loop: it returns whether it did (then this
  /// returns once the loop has handled it and waits again).
  template <typename Action>
  void stepIf(Action action) {
    const uint64_t seen = waits();
    if (action()) settleAfter(seen);
  }

  /// Moves time forward in one jump (a stalled machine, when `d` spans several periods).
  void advance(Clock::duration d) {
    step([&] {
      std::mutex* loop_mutex = nullptr;
      std::function<void()> wake;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        now_ += d;
        loop_mutex = loop_mutex_;
        wake = wake_;
      }
      // Taking the loop's mutex first: the loop is either before its time check or waiting.
      std::lock_guard<std::mutex> lock(*loop_mutex);
      wake();
    });
  }

  /// Moves time forward one loop period at a time, `periods` times.
  void tick(int periods, Clock::duration period = std::chrono::milliseconds(20)) {
    for (int i = 0; i < periods; ++i) advance(period);
  }

 private:
  void enterWait(std::unique_lock<std::mutex>& loop_lock, std::function<void()> wake) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      loop_mutex_ = loop_lock.mutex();
      wake_ = std::move(wake);
      ++waits_;
      waiting_ = true;
    }
    idle_.notify_all();
  }
  void leaveWait() {
    std::lock_guard<std::mutex> lock(mutex_);
    waiting_ = false;
  }

  uint64_t waits() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return waits_;
  }
  void settleAfter(uint64_t seen) {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [&] { return waiting_ && waits_ > seen; });
  }

  mutable std::mutex mutex_;
  std::condition_variable idle_;
  Clock::time_point now_;
  std::mutex* loop_mutex_ = nullptr;
  std::function<void()> wake_;  ///< ends the loop's wait (its condition variable or LoopWake)
  uint64_t waits_ = 0;
  bool waiting_ = false;
};

}  // namespace serial_robot_driver::core
