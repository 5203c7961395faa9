// core::LoopWake: what ends the base loop's wait. A notification made under the worker's mutex
// after it looked ends its wait; one it has already seen ends none; the deadline ends the rest.
// The deadlines that must not be reached are long (30 s): a lost notification fails the test
// rather than only slowing it.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "serial_robot_driver/core/loop_wake.h"

namespace serial_robot_driver::core {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

TEST(LoopWake, TheDeadlineEndsAWaitNobodyEnds) {
  std::mutex mutex;
  LoopWake wake;
  std::unique_lock<std::mutex> lock(mutex);
  EXPECT_FALSE(wake.waitUntil(lock, Clock::now() + milliseconds(20)));
  EXPECT_TRUE(lock.owns_lock());
  EXPECT_FALSE(wake.waitUntil(lock, Clock::now() - seconds(1)));  // already past
}

TEST(LoopWake, AChangeMadeWhileTheWorkerLooksEndsItsWait) {
  std::mutex mutex;
  LoopWake wake;
  bool command_pending = false;
  std::unique_lock<std::mutex> lock(mutex);
  // The notifier blocks on the mutex the worker holds until the wait releases it: the
  // notification comes after the worker looked, as an e-stop between two ticks does.
  std::thread notifier([&] {
    {
      std::lock_guard<std::mutex> guard(mutex);
      command_pending = true;
    }
    wake.notify();
  });
  while (!command_pending) {
    ASSERT_TRUE(wake.waitUntil(lock, Clock::now() + seconds(30))) << "the notification was lost";
  }
  lock.unlock();
  notifier.join();
}

TEST(LoopWake, ANotificationTheWorkerHasSeenEndsNoWait) {
  std::mutex mutex;
  LoopWake wake;
  wake.notify();  // for a change the worker is about to see under its lock
  wake.notify();
  std::unique_lock<std::mutex> lock(mutex);
  EXPECT_FALSE(wake.waitUntil(lock, Clock::now() + milliseconds(20)));
}

TEST(LoopWake, NotificationsDuringOneWaitEndOnlyThatWait) {
  std::mutex mutex;
  LoopWake wake;
  std::atomic<bool> waiting{false};
  std::unique_lock<std::mutex> lock(mutex);
  std::thread notifier([&] {
    // Under the mutex, so the worker cannot look again before all three are made.
    std::lock_guard<std::mutex> guard(mutex);
    for (int i = 0; i < 3; ++i) wake.notify();
  });
  EXPECT_TRUE(wake.waitUntil(lock, Clock::now() + seconds(30)));
  notifier.join();
  EXPECT_FALSE(wake.waitUntil(lock, Clock::now() + milliseconds(20)));
}

TEST(LoopWake, WaitWithoutADeadlineEndsOnANotification) {
  std::mutex mutex;
  LoopWake wake;
  bool advanced = false;
  std::unique_lock<std::mutex> lock(mutex);
  std::thread notifier([&] {
    std::lock_guard<std::mutex> guard(mutex);
    advanced = true;
    wake.notify();
  });
  while (!advanced) wake.waitUntil(lock, Clock::time_point::max());
  EXPECT_TRUE(lock.owns_lock());
  lock.unlock();
  notifier.join();
}

TEST(LoopWake, ManyNotificationsBeforeTheWorkerLooksEndNoWait) {
  std::mutex mutex;
  LoopWake wake;
  // A worker not started yet while commands arrive: it must not collect one wake-up per command.
  std::thread notifier([&] {
    for (int i = 0; i < 10000; ++i) wake.notify();
  });
  notifier.join();
  std::unique_lock<std::mutex> lock(mutex);
  EXPECT_FALSE(wake.waitUntil(lock, Clock::now() + milliseconds(20)));
  EXPECT_FALSE(wake.waitUntil(lock, Clock::now() + milliseconds(20)));
}

}  // namespace
}  // namespace serial_robot_driver::core
