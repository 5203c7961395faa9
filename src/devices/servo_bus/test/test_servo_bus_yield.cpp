// A stop waits for at most one bus transaction attempt, whoever holds the bus: a call that keeps
// the bus across several transactions (servo/reset_user_data's RESET and PING chain, servo/write's
// write and read-back) hands it to the stop before its next transaction; a stop service's call
// (BusPriority::kStop) is urgent work like the e-stop's stop; a wait for a motion's completion
// gives way to it. On the scripted bus of servo_bus_rig.h: the transaction in flight is a frame
// held "on the wire" until the test releases it, and the order of the frames written is checked.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/bus_mutex.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "support/golden_frames.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using namespace golden::servo;  // NOLINT: the shared golden frames

SpinRequest stopOf0() {
  SpinRequest stop;
  stop.id = 0;
  stop.mode = 0;  // speed 0: kSpin0StopSpeed0
  return stop;
}

class ServoBusYieldTest : public ServoBusTest {
 protected:
  /// An armed bus whose silent servo costs `attempts` RESET_USER_DATA and PING 0 pairs.
  void makeArmedBus(int attempts) {
    makeBus({}, [attempts](ServoBusConfig& config) {
      config.client.allow_dangerous_writes = true;
      config.client.retries = attempts - 1;
    });
    bus_->start();
  }
  /// `operation` on a thread of its own, its first frame `first` held on the wire: the one
  /// transaction attempt in flight. Returns once that frame is written.
  std::thread runHolding(const Bytes& first, std::function<void()> operation) {
    holdOnTheWire(first);
    std::thread runner(std::move(operation));
    EXPECT_TRUE(waitFor([&] { return countWritten(first) == 1; }));
    return runner;
  }
  /// A manual stop of servo 0 (servo/spin mode 0) on a thread of its own, once it waits for the
  /// bus.
  std::thread manualStopWaiting(ServoStatus* stopped) {
    std::thread stopper([this, stopped] { *stopped = bus_->spin(stopOf0()); });
    EXPECT_TRUE(waitFor([&] { return bus_->client().stopsWaiting() == 1; }));
    return stopper;
  }
};

// The user's report: reset_user_data of a silent servo runs RESET, PING 0, RESET, PING 0, ... under
// one bus lock, and the e-stop's stop waited for all of them. It goes right after the attempt in
// flight now.
TEST_F(ServoBusYieldTest, TheEStopsStopGoesAfterTheResetAttemptInFlightNotAfterTheChain) {
  makeArmedBus(3);
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  ServoStatus reset;
  std::thread resetter =
      runHolding(kResetUserData3, [&] { reset = bus_->client().resetUserData(3); });
  bus_->setMotionLocked(true);
  releaseTheWire();
  resetter.join();
  ASSERT_TRUE(waitFor([&] { return countWritten(kSpin0StopSpeed0) >= 1; }));
  EXPECT_EQ(reset.error, ServoError::kTimeout) << reset.message;
  EXPECT_EQ(firstIndexOf(kSpin0StopSpeed0), firstIndexOf(kResetUserData3) + 1)
      << "the stop waited for more than the attempt in flight";
  bus_->setMotionLocked(false);
  bus_->shutdown();
}

// servo/spin mode 0 is urgent work too: it goes before reset_user_data's next transaction.
TEST_F(ServoBusYieldTest, AManualStopGoesAfterTheResetAttemptInFlightNotAfterTheChain) {
  makeArmedBus(3);
  ServoStatus reset;
  std::thread resetter =
      runHolding(kResetUserData3, [&] { reset = bus_->client().resetUserData(3); });
  ServoStatus stopped;
  std::thread stopper = manualStopWaiting(&stopped);
  releaseTheWire();
  stopper.join();
  resetter.join();
  EXPECT_TRUE(stopped.ok()) << stopped.message;
  EXPECT_EQ(firstIndexOf(kSpin0StopSpeed0), firstIndexOf(kResetUserData3) + 1);
  EXPECT_LT(firstIndexOf(kSpin0StopSpeed0), firstIndexOf(kPing0)) << "the stop waited for a PING";
  EXPECT_EQ(countWritten(kPing0), 3u);
  bus_->shutdown();
}

// servo/write's WRITE_DATA and its read-back: a manual stop asked during the write goes between
// them; the write still completes and is read back.
TEST_F(ServoBusYieldTest, AManualStopGoesBetweenAWriteAndItsReadBack) {
  answers_[kWriteSoftStart3] = kWriteSoftStart3Ok;
  answers_[kReadSoftStart3] = kReadSoftStart3Reply300;
  makeBus({});
  bus_->start();
  ServoStatus write;
  std::thread writer = runHolding(
      kWriteSoftStart3, [&] { write = bus_->client().writeParam(3, "soft_start_time", 300); });
  ServoStatus stopped;
  std::thread stopper = manualStopWaiting(&stopped);
  releaseTheWire();
  stopper.join();
  writer.join();
  EXPECT_TRUE(stopped.ok()) << stopped.message;
  EXPECT_TRUE(write.ok()) << write.message;
  EXPECT_EQ(written(), (std::vector<Bytes>{kWriteSoftStart3, kSpin0StopSpeed0, kReadSoftStart3}));
  bus_->shutdown();
}

// A call waiting a minute for a motion's completion gives way to a manual stop at once.
TEST_F(ServoBusYieldTest, AWaitForAMotionsCompletionGivesWayToAManualStop) {
  makeBus({});
  bus_->start();
  RotateRequest rotate;
  rotate.id = 2;
  rotate.angle_deg = 90.0;
  rotate.interval_ms = 60000;
  rotate.wait = true;
  ServoStatus waited;
  std::thread mover([&] { waited = bus_->rotate(rotate); });
  ASSERT_TRUE(waitFor([&] { return written().size() == 1; }));
  ASSERT_TRUE(bus_->spin(stopOf0()).ok());
  mover.join();
  EXPECT_EQ(waited.error, ServoError::kPreempted) << waited.message;
  EXPECT_EQ(written().back(), kSpin0StopSpeed0);
  bus_->shutdown();
}

// The thread that serves the stop services may itself be waiting for a motion (servo/spin with
// wait): a stop call queued for it ends that wait, or the stop would wait for the whole motion.
TEST_F(ServoBusYieldTest, AWaitForAMotionsCompletionGivesWayToAStopCallQueued) {
  std::atomic<bool> stop_call_queued{false};
  makeBus({});
  bus_->client().setStopCallsQueued([&] { return stop_call_queued.load(); });
  bus_->start();
  SpinRequest spin = continuousSpin0();
  spin.mode = 3;  // 60 s
  spin.value = 60000;
  spin.wait = true;
  ServoStatus waited;
  std::thread mover([&] { waited = bus_->spin(spin); });
  ASSERT_TRUE(waitFor([&] { return written().size() == 1; }));
  stop_call_queued = true;
  bus_->client().stopCallQueued();
  mover.join();
  EXPECT_EQ(waited.error, ServoError::kPreempted) << waited.message;
  bus_->shutdown();
}

// Urgent work waiting for the holder keeps a background wait (the poll) waiting instead of making
// it give way: only the worker's own stops (requestUrgent) do that, or the worker, which must go on
// reading the port for the holder, would spin on a lock that refuses it at once.
TEST(BusMutexYieldTest, BackgroundWorkWaitsBehindAWaitingStopInsteadOfGivingUp) {
  BusMutex bus;
  std::mutex order_mutex;
  std::vector<std::string> order;
  const auto record = [&](const char* who) {
    std::lock_guard<std::mutex> lock(order_mutex);
    order.push_back(who);
  };
  bus.lock();  // a transaction in progress
  std::thread stop([&] {
    bus.lockUrgent();
    record("stop");
    bus.unlock();
  });
  while (bus.urgentWaiting() == 0) std::this_thread::yield();
  bool background_took_it = false;
  std::thread background([&] {
    background_took_it = bus.lockBackground();
    record("background");
    if (background_took_it) bus.unlock();
  });
  bus.yieldToUrgent();  // the holder's next attempt: the stop goes first
  record("holder");
  bus.unlock();
  stop.join();
  background.join();
  EXPECT_TRUE(background_took_it);
  EXPECT_EQ(order, (std::vector<std::string>{"stop", "holder", "background"}));
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
