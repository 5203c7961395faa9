// The ServoBus's rules under the e-stop (motion_safety.h), on the scripted bus of servo_bus_rig.h:
// a motion accepted before an e-stop never goes out after it, even once released; the e-stop's
// stops are written again at a steady pace while it holds (a slow motion passes for rest);
// releasing it keeps the stops never written; broadcast motions are refused; address changes and
// motion settings are refused while the servo moves or the e-stop holds, and an address change
// takes the stop bookkeeping along; relax is allowed under the e-stop and satisfies the stop.
// Frames by hand from docs/protocols.md (SPIN: 12 4C 07 06 | id, method, speed u16, value u16 |
// sum of the bytes before it).
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

using namespace golden::servo;  // NOLINT: the shared golden frames

// 90.4 deg = 904 = 0x0388: 05+1C+0A+03+00+88+03 = 0xB9 (0.2 deg from 90.2: "at rest").
const Bytes kReadAngle0Reply904 = {0x05, 0x1C, 0x0A, 0x03, 0x00, 0x88, 0x03, 0xB9};
// Servo 3 counter-clockwise continuous at 100 deg/s: 12+4C+07+06+03+01+64 = 0xD3.
const Bytes kSpin3CcwContinuous = {0x12, 0x4C, 0x07, 0x06, 0x03, 0x01,
                                   0x64, 0x00, 0x00, 0x00, 0xD3};
// SPIN stops at speed 0: 12+4C+07+06+id.
const Bytes kSpin3StopSpeed0 = {0x12, 0x4C, 0x07, 0x06, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x6E};
const Bytes kSpin5StopSpeed0 = {0x12, 0x4C, 0x07, 0x06, 0x05, 0x00, 0x00, 0x00, 0x00, 0x00, 0x70};
// Broadcast SPIN continuous at 100 deg/s: 12+4C+07+06+FF+01+64 = 0x1CF -> CF.
const Bytes kSpinBroadcastContinuous = {0x12, 0x4C, 0x07, 0x06, 0xFF, 0x01,
                                        0x64, 0x00, 0x00, 0x00, 0xCF};

SpinRequest spinOf(uint8_t id, uint8_t mode) {
  SpinRequest spin;
  spin.id = id;
  spin.mode = mode;
  spin.speed_dps = mode == 0 ? 0 : 100;
  return spin;
}

// The user's report: a spin waits for the bus behind a slow transaction, the e-stop engages and
// is released before the spin's turn comes. The spin was accepted before the e-stop: dropped.
TEST_F(ServoBusTest, ACallAcceptedBeforeAnEStopIsDroppedEvenWhenReleasedBeforeItsTurn) {
  makeBus({});
  bus_->start();
  ServoStatus spin;
  ASSERT_TRUE(callWaitingBehindPing3([&] { spin = bus_->spin(continuousSpin0()); }));
  bus_->setMotionLocked(true);
  bus_->setMotionLocked(false);
  releaseTheWireAndJoin();
  EXPECT_EQ(spin.error, ServoError::kMotionRefused);
  EXPECT_NE(spin.message.find("e-stop engaged after this command was accepted"), std::string::npos)
      << spin.message;
  EXPECT_EQ(countWritten(kSpin0CcwContinuous), 0u) << "a motion went out after the e-stop";
  EXPECT_TRUE(bus_->spin(continuousSpin0()).ok()) << "a command after the release moves";
  EXPECT_EQ(countWritten(kSpin0CcwContinuous), 1u);
  bus_->shutdown();
}

// The same for a queued move (servo_commands, a trajectory segment) the worker waits to write.
TEST_F(ServoBusTest, AQueuedMoveAcceptedBeforeAnEStopIsDroppedEvenWhenReleased) {
  makeBus({});
  ASSERT_TRUE(moveQueuedBehindPing3());
  bus_->setMotionLocked(true);
  bus_->setMotionLocked(false);
  releaseTheWireAndJoin();
  ASSERT_TRUE(waitFor([&] { return bus_->stats().moves_failed == 1; }));
  bus_->shutdown();
  EXPECT_EQ(countWritten(kRotate2To90In500), 0u);
}

// Two looks 0.1 s apart that differ by 0.2 deg: a servo at rest, or one turning at 2 deg/s whose
// stop was lost. While the e-stop holds its stop is written again every kStopRepeat, the servo
// no longer listed as pending; the release ends the repeats.
TEST_F(ServoBusTest, TheEStopsStopIsWrittenAgainAtASteadyPaceWhileItHolds) {
  scripted_answers_[kReadAngle0] = {kReadAngle0Reply902, kReadAngle0Reply904};
  makeBus({});
  bus_->start();
  clock_->waitForLoop();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  clock_->step([&] { bus_->setMotionLocked(true); });  // stop, first look (90.2)
  clock_->advance(ServoBus::kStopSettle);              // second look (90.4): "at rest"
  EXPECT_TRUE(bus_->pendingStops().empty());
  ASSERT_EQ(countWritten(kSpin0StopSpeed0), 1u);
  clock_->advance(StopKeeper::kStopRepeat);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 2u) << "a slow motion passed for rest";
  clock_->advance(StopKeeper::kStopRepeat);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 3u);
  EXPECT_TRUE(bus_->pendingStops().empty());
  bus_->setMotionLocked(false);
  clock_->advance(StopKeeper::kStopRepeat * 2);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 3u) << "released: no more repeats";
  bus_->shutdown();
}

// Engaged and released while the cable is out: the stop never went out, so it is kept and is the
// first frame once the port is back.
TEST_F(ServoBusTest, AReleaseKeepsTheStopThatWasNeverWritten) {
  ASSERT_TRUE(spinThenEStopWithThePortDown());
  bus_->setMotionLocked(false);
  ASSERT_EQ(bus_->pendingStops().size(), 1u) << "the release dropped a stop never written";
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 0u);
  portBackUp();
  EXPECT_EQ(firstIndexOf(kSpin0StopSpeed0), 1u) << "right after the spin";
  clock_->advance(ServoBus::kStopSettle);
  EXPECT_TRUE(bus_->pendingStops().empty());
  bus_->shutdown();
}

// Nothing answers a broadcast: the driver could not tell which servos it set moving.
TEST_F(ServoBusTest, BroadcastMotionsAreRefusedButABroadcastStopIsNot) {
  makeBus({});
  const ServoStatus spin = bus_->spin(spinOf(255, 1));
  EXPECT_EQ(spin.error, ServoError::kInvalidArgument);
  EXPECT_NE(spin.message.find("broadcast"), std::string::npos) << spin.message;
  RotateRequest rotate;
  rotate.id = 255;
  rotate.angle_deg = 10.0;
  EXPECT_EQ(bus_->rotate(rotate).error, ServoError::kInvalidArgument);
  MoveRequest move;
  move.id = 255;
  move.angle_deg = 10.0;
  EXPECT_EQ(bus_->move(move).error, ServoError::kInvalidArgument);
  EXPECT_EQ(bus_->hold({255}).error, ServoError::kInvalidArgument);
  EXPECT_TRUE(written().empty()) << "a broadcast motion reached the bus";
  EXPECT_EQ(countWritten(kSpinBroadcastContinuous), 0u);
  EXPECT_TRUE(bus_->spin(spinOf(255, 0)).ok()) << "a broadcast stop is a stop";
  EXPECT_TRUE(bus_->commandedIds().empty());
  bus_->shutdown();
}

// A moving servo keeps its address and its motion settings; under the e-stop no servo changes
// them; a non-motion setting is written either way.
TEST_F(ServoBusTest, AddressChangesAndMotionSettingsAreRefusedWhileTheServoMovesOrUnderTheEStop) {
  makeBus({}, [](ServoBusConfig& config) { config.client.allow_dangerous_writes = true; });
  ASSERT_TRUE(bus_->spin(spinOf(3, 1)).ok());
  const std::size_t before = written().size();
  const ServoStatus moving = bus_->writeParam(3, "servo_id", 5);
  EXPECT_EQ(moving.error, ServoError::kMotionRefused);
  EXPECT_NE(moving.message.find("while it moves"), std::string::npos) << moving.message;
  EXPECT_EQ(bus_->writeParam(3, "angle_limit_high", 900).error, ServoError::kMotionRefused);
  EXPECT_EQ(bus_->resetUserData(3).error, ServoError::kMotionRefused);
  EXPECT_EQ(written().size(), before) << "a refused write reached the bus";

  bus_->setMotionLocked(true);
  const ServoStatus locked = bus_->writeParam(2, "angle_mid_offset", 10);
  EXPECT_EQ(locked.error, ServoError::kMotionRefused);
  EXPECT_NE(locked.message.find("e_stop"), std::string::npos) << locked.message;
  EXPECT_EQ(bus_->resetUserData(2).error, ServoError::kMotionRefused);
  EXPECT_NE(bus_->writeParam(2, "soft_start_time", 10).error, ServoError::kMotionRefused)
      << "not a motion setting";
  bus_->setMotionLocked(false);
  bus_->shutdown();
}

// Servo 3, set moving and stopped since, moves to id 5: the e-stop stops it at id 5.
TEST_F(ServoBusTest, AnAddressChangeOfARestingServoTakesItsStopAlong) {
  answers_[kWriteServoId3To5] = kWriteServoId3To5Ok;
  answers_[kReadServoId5] = kReadServoId5Reply;
  makeBus({}, [](ServoBusConfig& config) { config.client.allow_dangerous_writes = true; });
  ASSERT_TRUE(bus_->spin(spinOf(3, 1)).ok());
  ASSERT_TRUE(bus_->spin(spinOf(3, 0)).ok());  // the manual stop: at rest
  ASSERT_EQ(countWritten(kSpin3StopSpeed0), 1u);
  const ServoStatus changed = bus_->writeParam(3, "servo_id", 5);
  ASSERT_TRUE(changed.ok()) << changed.message;
  EXPECT_EQ(bus_->commandedIds(), std::vector<uint8_t>{5});
  bus_->setMotionLocked(true);  // no worker: the stops are written here
  EXPECT_EQ(countWritten(kSpin5StopSpeed0), 1u) << "the stop did not follow the servo";
  EXPECT_EQ(countWritten(kSpin3StopSpeed0), 1u) << "a stop went to the old, empty address";
  bus_->setMotionLocked(false);
  bus_->shutdown();
}

// Torque off moves nothing: allowed under the e-stop; the relaxed servo's stop is satisfied and
// no longer repeated (a SPIN stop would give it its torque back).
TEST_F(ServoBusTest, RelaxIsAllowedUnderTheEStopAndSatisfiesTheStop) {
  makeBus({});
  bus_->start();
  clock_->waitForLoop();
  ASSERT_TRUE(bus_->spin(continuousSpin0()).ok());
  clock_->step([&] { bus_->setMotionLocked(true); });
  clock_->advance(ServoBus::kStopSettle);
  ASSERT_EQ(countWritten(kSpin0StopSpeed0), 1u);
  const ServoStatus relaxed = bus_->damping(0, 500, false);
  ASSERT_TRUE(relaxed.ok()) << relaxed.message;
  EXPECT_EQ(countWritten(kDamping0At500), 1u);
  EXPECT_TRUE(bus_->commandedIds().empty());
  clock_->advance(StopKeeper::kStopRepeat * 2);
  EXPECT_EQ(countWritten(kSpin0StopSpeed0), 1u) << "the relaxed servo was stopped again";
  EXPECT_TRUE(bus_->pendingStops().empty());
  bus_->setMotionLocked(false);
  bus_->shutdown();
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
