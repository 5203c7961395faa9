#include "serial_robot_driver/devices/servo_bus/bus_mutex.h"

#include <chrono>
#include <utility>

namespace serial_robot_driver::devices::servo_bus {

namespace {

/// The longest a reader thread waiting for the bus pumps before it looks again; unlock() wakes it
/// sooner.
constexpr std::chrono::milliseconds kReaderWaitSlice{10};

}  // namespace

template <typename Predicate>
void BusMutex::waitTurn(std::unique_lock<std::mutex>& lock, Predicate free) {
  while (!free()) {
    if (pump_ == nullptr || !pump_->on_reader_thread()) {
      released_.wait(lock);
      continue;
    }
    // The reader thread: whoever holds the bus may be waiting for an answer only it can read.
    reader_waiting_ = true;
    lock.unlock();
    const bool port_up = pump_->pump(core::Clock::now() + kReaderWaitSlice);
    lock.lock();
    // A port that is down has nothing to read: the holder's write fails at once, so this wait
    // is short, but it must not spin.
    if (!port_up) released_.wait_for(lock, kReaderWaitSlice, free);
  }
}

void BusMutex::lock() {
  std::unique_lock<std::mutex> lock(mutex_);
  ++waiting_;
  waitTurn(lock, [this] { return !held_ && !urgentAhead() && yielded_ == 0; });
  --waiting_;
  held_ = true;
}

bool BusMutex::lockBackground() {
  std::unique_lock<std::mutex> lock(mutex_);
  waitTurn(lock, [this] {
    return urgent_ || (!held_ && waiting_ == 0 && yielded_ == 0 && urgent_waiting_ == 0);
  });
  if (urgent_) return false;  // a stop is coming: the poll gives way and is due again at once
  held_ = true;
  return true;
}

bool BusMutex::lockUnlessUrgent() {
  std::unique_lock<std::mutex> lock(mutex_);
  ++waiting_;
  waitTurn(lock, [this] { return urgent_ || (!held_ && yielded_ == 0 && urgent_waiting_ == 0); });
  --waiting_;
  if (urgent_) return false;
  held_ = true;
  return true;
}

void BusMutex::lockUrgent() {
  std::unique_lock<std::mutex> lock(mutex_);
  ++urgent_waiting_;
  waitTurn(lock, [this] { return !held_; });
  --urgent_waiting_;
  held_ = true;
}

void BusMutex::requestUrgent() {
  std::unique_lock<std::mutex> lock(mutex_);
  urgent_ = true;
  wakeWaiters(lock);  // a background wait gives up
}

void BusMutex::endUrgent() {
  std::unique_lock<std::mutex> lock(mutex_);
  urgent_ = false;
  wakeWaiters(lock);
}

bool BusMutex::urgentRequested() {
  std::lock_guard<std::mutex> lock(mutex_);
  return urgent_;
}

void BusMutex::yieldToUrgent() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!urgentAhead()) return;
  held_ = false;
  ++yielded_;
  wakeWaiters(lock);
  waitTurn(lock, [this] { return !held_ && !urgentAhead(); });
  --yielded_;
  held_ = true;
}

int BusMutex::foregroundWaiting() {
  std::lock_guard<std::mutex> lock(mutex_);
  return waiting_;
}

int BusMutex::urgentWaiting() {
  std::lock_guard<std::mutex> lock(mutex_);
  return urgent_waiting_;
}

void BusMutex::unlock() {
  std::unique_lock<std::mutex> lock(mutex_);
  held_ = false;
  wakeWaiters(lock);
}

void BusMutex::wakeWaiters(std::unique_lock<std::mutex>& lock) {
  // Returns with `lock` held, as it came: yieldToUrgent() goes on waiting with it.
  released_.notify_all();
  if (!std::exchange(reader_waiting_, false)) return;
  lock.unlock();
  pump_->wake();  // the reader pumping its port: its read returns at once
  lock.lock();
}

}  // namespace serial_robot_driver::devices::servo_bus
