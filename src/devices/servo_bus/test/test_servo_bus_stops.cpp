// The ServoBus's stops and its motion gate, on the scripted bus of servo_bus_rig.h: whether a
// motion frame may be written is decided when it is written (a call or a queued move that waited
// for the bus behind a held transaction is dropped when the e-stop came meanwhile), the e-stop's
// stop jumps the queue of calls, and a stop is written again until the servo is seen at rest
// (a stop the servo did not act on, a stop written while the port was down).
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "support/golden_frames.h"
#include "support/servo_bus_rig.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using std::chrono::milliseconds;
using namespace golden::servo;  // NOLINT: the shared golden frames

// The user's report: servo/spin waits for the bus behind a slow transaction, the e-stop comes, and
// the SPIN went out after it. Now the frame is refused when its turn comes, and the call says so.
TEST_F(ServoBusTest, ACallThatWaitedForTheBusIsRefusedWhenTheEStopCameMeanwhile) {
  makeBus({});
  bus_->start();
  ServoStatus spin;
  ASSERT_TRUE(callWaitingBehindPing3([&] { spin = bus_->spin(continuousSpin0()); }));
  bus_->setMotionLocked(true);  // returns at once: nothing to stop yet, the bus is still held
  releaseTheWireAndJoin();
  EXPECT_EQ(spin.error, ServoError::kMotionRefused);
  EXPECT_NE(spin.message.find("e_stop engaged"), std::string::npos) << spin.message;
  EXPECT_NE(spin.message.find("not written"), std::string::npos) << spin.message;
  EXPECT_EQ(countWritten(kSpin0CcwContinuous), 0u) << "a motion went out after the e-stop";
  EXPECT_EQ(bus_->motionRefusedAtWrite(), 1u);
  EXPECT_TRUE(bus_->commandedIds().empty());
  bus_->shutdown();
}

// A queued move (servo_commands, a trajectory segment) taken by the worker before the e-stop and
// written after it: dropped at the write, reported as a failed move.
TEST_F(ServoBusTest, AQueuedMoveThatWaitedForTheBusIsDroppedAtTheWrite) {
  makeBus({});
  ASSERT_TRUE(moveQueuedBehindPing3()) << "the worker waits for the bus with the move";
  bus_->setMotionLocked(true);
  releaseTheWireAndJoin();
  ASSERT_TRUE(waitFor([&] { return bus_->stats().moves_failed == 1; }));
  bus_->shutdown();
  EXPECT_EQ(countWritten(kRotate2To90In500), 0u);
  ASSERT_EQ(failed_moves_.size(), 1u);
  EXPECT_EQ(failed_moves_[0].second, ServoError::kMotionRefused);
}

// The e-stop's stop waits for the one transaction on the wire, never for the calls queued behind
// it; the e-stop itself returns without waiting for the bus at all.
TEST_F(ServoBusTest, TheEStopsStopGoesBeforeTheCallsWaitingForTheBus) {
  const Bytes kPing5Reply = {0x05, 0x1C, 0x01, 0x01, 0x05, 0x28};
  answers_[kPing5] = kPing5Reply;
  makeBus({});
  bus_->start();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  ASSERT_TRUE(callWaitingBehindPing3([&] { bus_->client().ping(5); }));
  bus_->setMotionLocked(true);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 0u) << "the e-stop waited for the bus";
  releaseTheWireAndJoin();
  ASSERT_TRUE(waitFor([&] { return countWritten(kSpin0StopSpeed0) == 1; }));
  EXPECT_LT(firstIndexOf(kSpin0StopSpeed0), firstIndexOf(kPing5)) << "the stop waited for a call";
  EXPECT_EQ(firstIndexOf(kSpin0StopSpeed0), firstIndexOf(kPing3) + 1);
  bus_->shutdown();
}

// The stop is kept until the servo is seen at rest: an angle that still changes after it (the
// servo did not hear it) has it written again; two equal angles confirm it.
TEST_F(ServoBusTest, AStopAfterWhichTheServoStillMovesIsWrittenAgain) {
  scripted_answers_[kReadAngle0] = {kReadAngle0Reply902, kReadAngle0Reply1000, kReadAngle0Reply1000,
                                    kReadAngle0Reply1000};
  makeBus({});
  bus_->start();
  clock_->waitForLoop();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  clock_->step([&] { bus_->setMotionLocked(true); });  // stop, first look (90.2)
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 1u);
  ASSERT_EQ(bus_->pendingStops().size(), 1u);
  clock_->advance(ServoBus::kStopSettle);  // second look: 100.0, still moving: written again
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 2u);
  ASSERT_EQ(bus_->pendingStops().size(), 1u);
  clock_->advance(ServoBus::kStopSettle);  // 100.0 twice: at rest
  EXPECT_TRUE(bus_->pendingStops().empty());
  ASSERT_EQ(stop_events_.size(), 2u);
  EXPECT_NE(stop_events_[0].second.message.find("still moving"), std::string::npos);
  EXPECT_TRUE(stop_events_[1].second.ok()) << stop_events_[1].second.message;
  bus_->setMotionLocked(false);
  bus_->shutdown();
}

// An e-stop engaged while the cable is out: the stop cannot be written, stays pending and says
// why; after the reconnect it is the first frame on the bus, before a call already waiting.
TEST_F(ServoBusTest, AStopThatCouldNotBeWrittenGoesFirstAfterTheReconnect) {
  const Bytes kPing5Reply = {0x05, 0x1C, 0x01, 0x01, 0x05, 0x28};
  answers_[kPing5] = kPing5Reply;
  ASSERT_TRUE(spinThenEStopWithThePortDown());
  ASSERT_EQ(bus_->pendingStops().size(), 1u);
  EXPECT_NE(bus_->pendingStops()[0].why.find("down"), std::string::npos);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 0u);
  portBackUp();
  std::thread caller([&] { bus_->client().ping(5); });
  caller.join();
  EXPECT_EQ(firstIndexOf(kSpin0StopSpeed0), 1u) << "right after the spin, before the PING";
  clock_->advance(ServoBus::kStopSettle);
  EXPECT_TRUE(bus_->pendingStops().empty());
  bus_->shutdown();
}

// A servo that does not answer after its stop is not known to have it: the stop is written again
// after a back-off, and the pending stop names what is missing.
TEST_F(ServoBusTest, AStopAfterWhichTheServoIsSilentIsWrittenAgainAfterABackoff) {
  makeBus({});
  bus_->start();
  clock_->waitForLoop();
  RotateRequest rotate;
  rotate.id = 2;
  rotate.angle_deg = 90.0;
  rotate.interval_ms = 500;
  ASSERT_TRUE(bus_->rotate(rotate).ok());
  clock_->step([&] { bus_->setMotionLocked(true); });
  EXPECT_EQ(countWritten(kSpin2StopSpeed0), 1u);
  ASSERT_EQ(bus_->pendingStops().size(), 1u);
  EXPECT_NE(bus_->pendingStops()[0].why.find("no answer"), std::string::npos)
      << bus_->pendingStops()[0].why;
  clock_->advance(milliseconds(99));
  EXPECT_EQ(countWritten(kSpin2StopSpeed0), 1u);
  clock_->advance(milliseconds(1));
  EXPECT_EQ(countWritten(kSpin2StopSpeed0), 2u);
  bus_->setMotionLocked(false);
  EXPECT_TRUE(bus_->pendingStops().empty()) << "released: nothing is held back any more";
  bus_->shutdown();
}

// A caller waiting for a motion's completion (wait = true) gives way to the stop at once instead
// of holding the bus for the whole motion.
TEST_F(ServoBusTest, AWaitForAMotionsCompletionGivesWayToTheStop) {
  makeBus({});
  bus_->start();
  RotateRequest rotate;
  rotate.id = 2;
  rotate.angle_deg = 90.0;
  rotate.interval_ms = 60000;  // a minute: the wait would hold the bus that long
  rotate.wait = true;
  ServoStatus waited;
  std::thread caller([&] { waited = bus_->rotate(rotate); });
  ASSERT_TRUE(
      waitFor([&] { return countWritten(kRotate2To90In500) == 0 && written().size() == 1; }));
  bus_->setMotionLocked(true);
  caller.join();
  EXPECT_EQ(waited.error, ServoError::kPreempted) << waited.message;
  ASSERT_TRUE(waitFor([&] { return countWritten(kSpin2StopSpeed0) >= 1; }));
  bus_->setMotionLocked(false);
  bus_->shutdown();
}

// An e-stop released before its stop went out: the stop still goes out (a release restarts
// nothing), and a call after it gets the bus (it would wait for the stop's turn for ever
// otherwise).
TEST_F(ServoBusTest, AReleaseBeforeTheStopWentOutStillStopsAndLeavesTheBusFreeForCalls) {
  const Bytes kPing5Reply = {0x05, 0x1C, 0x01, 0x01, 0x05, 0x28};
  answers_[kPing5] = kPing5Reply;
  makeBus({});
  bus_->start();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  std::thread holder = holdTheBusWithPing3();
  bus_->setMotionLocked(true);
  bus_->setMotionLocked(false);
  releaseTheWire();
  holder.join();
  EXPECT_TRUE(bus_->client().ping(5).ok());
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 1u);
  EXPECT_LT(firstIndexOf(kSpin0StopSpeed0), firstIndexOf(kPing5));
  bus_->shutdown();
}

// From the moment shutdown() decides the last words, a motion still waiting for the bus is refused.
TEST_F(ServoBusTest, ShutdownRefusesACallThatWaitedForTheBus) {
  makeBus({});
  ServoStatus spin;
  ASSERT_TRUE(callWaitingBehindPing3([&] { spin = bus_->spin(continuousSpin0()); }));
  std::thread closer([&] { bus_->shutdown(); });
  std::this_thread::sleep_for(milliseconds(20));  // shutdown() closes the gate first thing
  releaseTheWireAndJoin();
  closer.join();
  EXPECT_NE(spin.error, ServoError::kOk);
  EXPECT_EQ(countWritten(kSpin0CcwContinuous), 0u);
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
