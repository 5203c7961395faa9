// The servo bus's lock, by priority: who may put the next transaction on the half-duplex wire.
// A stop (urgent work) goes first and waits only for the holder, callers (the services) go next,
// background work (the polls) only while nobody else waits. ROS-free; ServoTransactions
// (servo_transactions.h) holds one.
//
// A holder may keep the bus across several transactions (a write and its read-back, a reset and
// the PING after it), but it calls yieldToUrgent() before each transaction attempt
// (ServoTransactions::transact does), so urgent work waits for the one attempt in flight only.
//
// Threading: any thread. With a ReaderPump, a wait on the link's reader thread pumps its port
// instead of sleeping, so the holder's answer, which only that thread can read, still arrives.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>

#include "serial_robot_driver/core/serial_link.h"

namespace serial_robot_driver::devices::servo_bus {

/// Who waits for the bus: a caller (a service) goes before background work (the poll). kWorker
/// is the bus's own worker, which writes the stops: it waits like a caller, but gives way to the
/// stops it is asked for (requestUrgent: kPreempted) instead of waiting for them, before the bus
/// is taken and between attempts. kStop is a stop service's call (a SPIN stop, a DAMPING, a hold):
/// urgent work like the worker's stops (lockUrgent), after the attempt in flight, before everyone
/// else.
enum class BusPriority { kCaller, kWorker, kBackground, kStop };

/// How the link's reader thread waits without sleeping on another thread: it reads its port
/// (SerialLink::pump) and is woken by wake() when what it waits for may have changed.
struct ReaderPump {
  std::function<bool()> on_reader_thread;
  /// Reads once, up to `until`; false when the port is down or stopping.
  std::function<bool(core::Clock::time_point until)> pump;
  std::function<void()> wake;
};

/// The bus lock, by priority: urgent work (a stop) goes first and waits only for the holder;
/// foreground callers (lock()) go next; background ones (lockBackground()) take the bus only while
/// nobody else waits for it. Usable with std::lock_guard (lock()/unlock()).
class BusMutex {
 public:
  void lock();
  void unlock();
  /// False, without the bus, when urgent work is asked while it waits (the poll gives way).
  bool lockBackground();
  /// A caller that gives way: false, without the bus, when urgent work is asked while it waits.
  bool lockUnlessUrgent();
  /// A stop: waits for the holder only (one transaction attempt at most), never for a queue.
  /// While it waits, the others wait behind it and the holder hands it the bus before its next
  /// attempt (yieldToUrgent); it does not make the worker give way (urgentRequested()).
  void lockUrgent();
  /// The worker's stops are coming: from now until endUrgent(), lock() and lockBackground() wait
  /// (a background wait, and the worker's, gives up) and a holder before its next attempt hands
  /// the bus over.
  void requestUrgent();
  void endUrgent();
  /// Whether the worker's stops are asked (requestUrgent), not a lockUrgent() waiting.
  bool urgentRequested();
  /// Before each transaction attempt of a holder: hands the bus to urgent work asked or waiting
  /// meanwhile and takes it back before any other caller.
  void yieldToUrgent();
  /// Foreground callers waiting right now (for tests and diagnostics).
  int foregroundWaiting();
  /// lockUrgent() calls waiting right now (for tests).
  int urgentWaiting();
  /// Set before any use: the reader thread pumps its port while it waits for the bus.
  void setReaderPump(const ReaderPump* pump) { pump_ = pump; }

 private:
  /// Waits (mutex_ held by `lock`) until `free` holds: on a condition variable, or pumping.
  template <typename Predicate>
  void waitTurn(std::unique_lock<std::mutex>& lock, Predicate free);
  void wakeWaiters(std::unique_lock<std::mutex>& lock);
  /// Urgent work asked or waiting (mutex_ held): nobody but it may take the bus.
  bool urgentAhead() const { return urgent_ || urgent_waiting_ > 0; }

  std::mutex mutex_;
  std::condition_variable released_;
  bool held_ = false;
  int waiting_ = 0;              ///< foreground callers waiting for the bus
  bool urgent_ = false;          ///< requestUrgent() .. endUrgent()
  int urgent_waiting_ = 0;       ///< lockUrgent() calls waiting for the holder
  int yielded_ = 0;              ///< holders that handed the bus to urgent work
  bool reader_waiting_ = false;  ///< the pumping reader thread waits: unlock() wakes it
  const ReaderPump* pump_ = nullptr;
};

}  // namespace serial_robot_driver::devices::servo_bus
