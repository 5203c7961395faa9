// ServoBus, the bus device without ROS: the move queue and the poll schedule with its back-off,
// on a manual clock (the worker thread runs; the test moves time) and a fake bus that records
// every frame and answers synchronously with golden frames.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "support/golden_frames.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using std::chrono::milliseconds;
using namespace golden::servo;  // NOLINT: the shared golden frames

TEST_F(ServoBusTest, PollsEachServoOncePerPeriod) {
  makeBus({0});
  bus_->start();
  clock_->waitForLoop();  // the first poll falls due at once
  EXPECT_EQ(countWritten(kReadAngle0), 1u);
  clock_->advance(milliseconds(99));
  EXPECT_EQ(countWritten(kReadAngle0), 1u);
  clock_->advance(milliseconds(1));
  EXPECT_EQ(countWritten(kReadAngle0), 2u);
  bus_->shutdown();

  ASSERT_EQ(angles_.size(), 2u);
  EXPECT_EQ(angles_[0].id, 0);
  EXPECT_DOUBLE_EQ(angles_[0].angle_deg, 90.2);
  EXPECT_EQ(bus_->stats().angles_polled, 2u);
  EXPECT_TRUE(bus_->stats().offline_ids.empty());
  EXPECT_TRUE(silent_.empty());
}

TEST_F(ServoBusTest, SilentServoIsAskedAgainAfterADoublingBackoff) {
  answers_.clear();
  makeBus({0});
  bus_->start();
  clock_->waitForLoop();
  EXPECT_EQ(countWritten(kReadAngle0), 1u);
  ASSERT_EQ(silent_.size(), 1u);
  EXPECT_EQ(silent_[0].first, 0);
  EXPECT_EQ(silent_[0].second, ServoBus::kFirstBackoff);
  EXPECT_EQ(bus_->stats().offline_ids, std::vector<uint8_t>{0});

  // Not at the poll period: only after the back-off.
  clock_->advance(milliseconds(499));
  EXPECT_EQ(countWritten(kReadAngle0), 1u);
  clock_->advance(milliseconds(1));
  EXPECT_EQ(countWritten(kReadAngle0), 2u);
  // Silent again: the back-off doubles, and the servo is reported once, not per poll.
  clock_->advance(milliseconds(999));
  EXPECT_EQ(countWritten(kReadAngle0), 2u);
  EXPECT_EQ(silent_.size(), 1u);

  // It answers again: back online and polled at the period.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    answers_[kReadAngle0] = kReadAngle0Reply902;
  }
  clock_->advance(milliseconds(1));
  EXPECT_EQ(countWritten(kReadAngle0), 3u);
  EXPECT_TRUE(bus_->stats().offline_ids.empty());
  clock_->advance(milliseconds(100));
  EXPECT_EQ(countWritten(kReadAngle0), 4u);
  bus_->shutdown();
  EXPECT_EQ(angles_.size(), 2u);
}

TEST_F(ServoBusTest, LatestTargetReplacesAQueuedOneAndMovesGoBeforeThePoll) {
  makeBus({0});
  MoveRequest first;
  first.id = 2;
  first.angle_deg = 10.0;
  MoveRequest latest = first;
  latest.angle_deg = 90.0;
  latest.interval_ms = 500;
  bus_->queueMoves({first});
  bus_->queueMoves({latest});
  EXPECT_EQ(bus_->stats().moves_replaced, 1u);

  bus_->start();
  clock_->waitForLoop();
  EXPECT_EQ(written(), (std::vector<Bytes>{kRotate2To90In500, kReadAngle0}));
  bus_->shutdown();
  EXPECT_EQ(bus_->stats().moves_sent, 1u);
}

TEST_F(ServoBusTest, RefusedMoveIsReportedAndNothingIsWritten) {
  makeBus({0});
  MoveRequest move;
  move.id = 2;
  move.angle_deg = 200.0;  // beyond a single-turn move's +-180
  bus_->queueMoves({move});
  bus_->start();
  clock_->waitForLoop();
  bus_->shutdown();
  EXPECT_EQ(written(), std::vector<Bytes>{kReadAngle0});
  ASSERT_EQ(failed_moves_.size(), 1u);
  EXPECT_EQ(failed_moves_[0].first, 2);
  EXPECT_EQ(failed_moves_[0].second, ServoError::kInvalidArgument);
  EXPECT_EQ(bus_->stats().moves_failed, 1u);
}

// A call waits for the one transaction in progress, never for the polls that fall due meanwhile:
// while servo 3's PING holds the bus, servo 0's poll falls due and another call (PING 5) comes;
// when the bus frees, the call goes first and the poll after it.
TEST_F(ServoBusTest, AWaitingCallGoesBeforeAPollThatFellDue) {
  const Bytes kPing5Reply = {0x05, 0x1C, 0x01, 0x01, 0x05, 0x28};
  answers_[kPing3] = kPing3Reply;
  answers_[kPing5] = kPing5Reply;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    gated_frame_ = kPing3;
  }
  makeBus({0});
  ServoStatus first, second;
  std::thread holder([&] { first = bus_->client().ping(3); });
  ASSERT_TRUE(waitFor([&] { return countWritten(kPing3) == 1; }));  // the transaction in progress
  bus_->start();  // servo 0's poll is due at once: the worker waits for the bus
  std::thread caller([&] { second = bus_->client().ping(5); });
  ASSERT_TRUE(waitFor([&] { return bus_->client().callersWaiting() == 1; }));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    gated_frame_.clear();
  }
  gate_opened_.notify_all();
  holder.join();
  caller.join();
  EXPECT_TRUE(first.ok()) << first.message;
  EXPECT_TRUE(second.ok()) << second.message;
  ASSERT_TRUE(waitFor([&] { return countWritten(kReadAngle0) == 1; }));  // the poll goes on
  bus_->shutdown();
  EXPECT_EQ(written(), (std::vector<Bytes>{kPing3, kPing5, kReadAngle0}));
}

TEST_F(ServoBusTest, AskedPollRateCountsTheServosNotInBackoffAtTheRateInForce) {
  answers_.clear();  // neither servo answers
  makeBus({0, 3});   // 10 Hz each
  EXPECT_DOUBLE_EQ(bus_->stats().asked_poll_rate, 20.0);
  ServoBusConfig faster = bus_->config();
  faster.poll_rate = 50.0;
  bus_->retune(faster);
  EXPECT_DOUBLE_EQ(bus_->stats().asked_poll_rate, 100.0);
  bus_->start();
  // Both are silent: once in back-off they are not asked at the poll rate any more.
  ASSERT_TRUE(waitFor([&] { return bus_->stats().offline_ids.size() == 2; }));
  EXPECT_DOUBLE_EQ(bus_->stats().asked_poll_rate, 0.0);
  bus_->shutdown();
}

TEST_F(ServoBusTest, ShutdownFailsLaterCallsAndIsIdempotent) {
  makeBus({});
  bus_->start();
  bus_->shutdown();
  bus_->shutdown();
  EXPECT_EQ(bus_->client().ping(3).error, ServoError::kShutdown);
  EXPECT_TRUE(written().empty());
}

// SPIN stop at speed 0 (the e-stop's and the shutdown's): 12 4C 07 06 | id 0, mode 0, speed 0,
// value 0 | sum 0x6B.

TEST_F(ServoBusTest, MotionLockStopsTheServosSetSpinningAndRefusesMotionUntilReleased) {
  makeBus({});
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  EXPECT_EQ(bus_->movingIds(), std::vector<uint8_t>{0});
  bus_->setMotionLocked(true);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 1u);
  EXPECT_TRUE(bus_->movingIds().empty());

  const ServoStatus refused = bus_->spin(continuousSpin0());
  EXPECT_EQ(refused.error, ServoError::kMotionRefused);
  EXPECT_NE(refused.message.find("e_stop"), std::string::npos) << refused.message;
  EXPECT_EQ(countWritten(kSpin0CcwContinuous), 1u) << "a refused command reached the bus";
  double angle = 0.0;
  EXPECT_TRUE(bus_->client().readAngle(0, &angle).ok()) << "reads still work";

  bus_->setMotionLocked(false);
  EXPECT_TRUE(bus_->spin(continuousSpin0()).ok());
  EXPECT_EQ(countWritten(kSpin0CcwContinuous), 2u);
}

// The last words: a stop to every servo set moving or positioned since start-up, then two looks at
// its angle (the servo is at rest: confirmed); later calls fail.
TEST_F(ServoBusTest, ShutdownStopsTheServosSetMovingAndLooksUntilTheyRest) {
  makeBus({});
  bus_->start();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  bus_->shutdown();
  EXPECT_EQ(written(),
            (std::vector<Bytes>{kSpin0CcwContinuous, kSpin0StopSpeed0, kReadAngle0, kReadAngle0}));
  EXPECT_TRUE(bus_->pendingStops().empty());
  EXPECT_EQ(bus_->spin(continuousSpin0()).error, ServoError::kShutdown);
}

// A servo stopped by hand was still positioned by the driver: it gets its stop at shutdown too.
TEST_F(ServoBusTest, ShutdownStopsAServoStoppedByHandAgain) {
  makeBus({});
  bus_->start();
  SpinRequest stop = continuousSpin0();
  stop.mode = 0;
  stop.speed_dps = 0;
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  ASSERT_TRUE(bus_->spin(stop).ok());
  EXPECT_TRUE(bus_->movingIds().empty());
  EXPECT_EQ(bus_->commandedIds(), std::vector<uint8_t>{0});
  bus_->shutdown();
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 2u);
}

TEST_F(ServoBusTest, ShutdownSaysNothingWhenNoServoWasCommanded) {
  makeBus({});
  bus_->start();
  double angle = 0.0;
  ASSERT_TRUE(bus_->client().readAngle(0, &angle).ok());
  bus_->shutdown();
  EXPECT_EQ(written(), std::vector<Bytes>{kReadAngle0});
}

TEST_F(ServoBusTest, RetunedPollRateAppliesFromTheNextPollAndTimingFromTheNextTransaction) {
  makeBus({0});
  bus_->start();
  clock_->waitForLoop();  // the first poll at t0; the next falls due at t0 + 100 ms
  clock_->advance(milliseconds(20));
  ServoBusConfig faster = bus_->config();
  faster.poll_rate = 50.0;  // every 20 ms
  faster.client.timeout = milliseconds(7);
  faster.client.retries = 2;
  clock_->step([&] { bus_->retune(faster); });
  EXPECT_EQ(countWritten(kReadAngle0), 1u);
  // Due 20 ms after the change, not at the 100 ms the old rate had scheduled.
  clock_->advance(milliseconds(20));
  EXPECT_EQ(countWritten(kReadAngle0), 2u);
  clock_->advance(milliseconds(20));
  EXPECT_EQ(countWritten(kReadAngle0), 3u);
  EXPECT_EQ(bus_->client().options().timeout, milliseconds(7));
  EXPECT_EQ(bus_->client().options().retries, 2);
  bus_->shutdown();
  EXPECT_EQ(angles_.size(), 3u);
}

TEST_F(ServoBusTest, RetunedSafetySettingsApplyFromTheirNextUse) {
  makeBus({0});  // health poll off (health_rate 0)
  EXPECT_TRUE(bus_->health().empty());
  bus_->start();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  ServoBusConfig next = bus_->settings();
  next.on_shutdown = ShutdownAction::kRelax;
  next.relax_power_mw = 500;
  next.health_rate = 1.0;
  next.protect = true;
  bus_->retune(next);
  EXPECT_EQ(bus_->config().on_shutdown, ShutdownAction::kStop) << "config() is the start-up one";
  EXPECT_EQ(bus_->settings().on_shutdown, ShutdownAction::kRelax);
  EXPECT_TRUE(bus_->settings().protect);
  EXPECT_EQ(bus_->health().size(), 1u) << "the health poll is on for the polled servo";
  bus_->shutdown();
  EXPECT_EQ(written().back(), kDamping0At500) << "on_shutdown relax at the retuned power";
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 0u);
}

}  // namespace

}  // namespace serial_robot_driver::devices::servo_bus
