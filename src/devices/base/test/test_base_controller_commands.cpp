// BaseController: the Reset/heartbeat cycle, cmd_vel handling, timeouts, services, immediate
// frames spaced by the line and the e-stop.
#include <gtest/gtest.h>

#include "support/base_controller_fixture.h"

namespace serial_robot_driver::devices::base {
namespace {

using namespace base_controller_test;  // NOLINT: the shared fixture

TEST_F(BaseControllerTest, FirstSpeedFrameIsPrecededByReset) {
  clock_->tick(1);
  ASSERT_EQ(frames_.size(), 2u);
  // Reset, SEQ 00: 55^AA^02^00^05^00 = F8
  EXPECT_EQ(frames_[0], golden::base::kResetSeq0);
  // zero speed, SEQ 01: XOR = 55^AA^09^01^01 = F6
  EXPECT_EQ(frames_[1], golden::base::kBoth0Seq1);
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_TRUE(sent_[0].reset_before);
  EXPECT_EQ(sent_[0].seq, 1);
  EXPECT_EQ(sent_[0].time, t0_ + milliseconds(20));
}

TEST_F(BaseControllerTest, HeartbeatFramesCountSequenceWithoutResets) {
  clock_->tick(300);
  ASSERT_EQ(frames_.size(), 301u);  // one Reset, then one speed frame per tick
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    EXPECT_EQ(frames_[i][3], static_cast<uint8_t>(i)) << "SEQ wraps 255 -> 0, one per frame";
  }
  EXPECT_EQ(controller_.stats().resets_sent, 1u);
  EXPECT_EQ(controller_.stats().loop_overruns, 0u);
}

TEST_F(BaseControllerTest, NewCommandGoesOutAtOnceWithEqualPositiveTicksWhenStraight) {
  command(*clock_, controller_, 0.1, 0.0);
  ASSERT_EQ(frames_.size(), 2u) << "sent before the first tick is due";
  // 0.1 m/s = 4.07 ticks per period -> 4 on the first frame; SEQ 01: XOR = F7 ^ 01 = F6
  EXPECT_EQ(frames_[1], golden::base::kBoth4Seq1);
  EXPECT_EQ(controller_.stats().immediate_frames, 1u);
}

TEST_F(BaseControllerTest, TurnInPlaceGivesOppositeTicks) {
  command(*clock_, controller_, 0.0, 1.0);  // wheels at -/+ 0.2 m/s
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_LT(sent_[0].ticks.left, 0);
  EXPECT_EQ(sent_[0].ticks.left, -sent_[0].ticks.right);
  EXPECT_EQ(sent_[0].ticks.right, 8);
}

TEST_F(BaseControllerTest, HugeCommandKeepsItsDirectionAtFullSpeed) {
  command(*clock_, controller_, 1e308, 1e308);  // the wheel sum would overflow to inf
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_NEAR(sent_[0].speeds.y(), 1.0, 1e-9) << "the faster wheel at max_wheel_speed";
  EXPECT_GT(sent_[0].speeds.x(), 0.0);
  EXPECT_LT(sent_[0].speeds.x(), 1.0);
  EXPECT_EQ(sent_[0].ticks.right, 41);  // 40.74 ticks per period, rounded on the first frame
}

TEST_F(BaseControllerTest, CommandTimesOutToZero) {
  command(*clock_, controller_, 0.5, 0.0);
  ASSERT_GT(sent_.back().ticks.left, 0);
  clock_->tick(24);  // 480 ms: cmd_vel_timeout is 0.5 s
  EXPECT_GT(sent_.back().ticks.left, 0);
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 0u);
  clock_->tick(6);  // 600 ms
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 1u);
}

TEST_F(BaseControllerTest, NonFiniteCommandIsRejectedAsZero) {
  command(*clock_, controller_, 0.5, 0.0);
  EXPECT_EQ(command(*clock_, controller_, std::nan(""), 0.0), CommandOutcome::kNotFinite);
  EXPECT_EQ(command(*clock_, controller_, 0.1, INFINITY), CommandOutcome::kNotFinite);
  clock_->tick(1);  // the latest command goes out by the next tick at the latest
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().rejected_commands, 2u);
}

TEST_F(BaseControllerTest, TimeoutErrorFrameMakesNextFrameReset) {
  clock_->tick(2);
  frames_.clear();
  // FF error status from the base, SEQ 07: 55^AA^02^07^FF^00 = 05
  const Bytes& error = golden::base::kErrorStatusSeq7;
  clock_->step([&] { controller_.onFrame(kFrames, error.data(), error.size(), clock_->now()); });
  clock_->tick(1);
  // The error wakes the loop: Reset, then the speed frame (rushed), then the tick's speed frame.
  ASSERT_EQ(frames_.size(), 3u);
  EXPECT_EQ(frames_[0][4], 0x05) << "Reset goes first";
  EXPECT_EQ(frames_[1][4], 0x01);
  EXPECT_EQ(frames_[2][4], 0x01) << "one Reset per error";
  EXPECT_TRUE(sent_[sent_.size() - 2].reset_before);
  EXPECT_FALSE(sent_.back().reset_before);
  EXPECT_EQ(controller_.stats().timeout_errors_received, 1u);
}

TEST_F(BaseControllerTest, OwnSendingGapOfOneSecondForcesReset) {
  clock_->tick(1);
  frames_.clear();
  clock_->advance(milliseconds(900));  // a stalled machine: no tick for 0.9 s
  ASSERT_EQ(frames_.size(), 1u) << "0.9 s gap: the base has not timed out";
  EXPECT_EQ(controller_.stats().loop_overruns, 1u);
  clock_->advance(milliseconds(1000));
  ASSERT_EQ(frames_.size(), 3u);
  EXPECT_EQ(frames_[1][4], 0x05);
}

TEST_F(BaseControllerTest, ReconnectForcesResetAndFailedWritesAreCounted) {
  clock_->tick(1);
  port_up_ = false;
  controller_.onLinkDown();
  clock_->tick(1);
  EXPECT_EQ(controller_.stats().write_failures, 1u);
  port_up_ = true;
  frames_.clear();
  clock_->step([&] { controller_.onLinkUp(); });  // the Reset goes out at once
  ASSERT_EQ(frames_.size(), 2u);
  EXPECT_EQ(frames_[0][4], 0x05);
}

TEST_F(BaseControllerTest, ResetAndClearEncodersServicesWriteTheirFrames) {
  EXPECT_TRUE(controller_.sendClearEncoders());
  EXPECT_TRUE(controller_.sendReset());
  ASSERT_EQ(frames_.size(), 2u);
  EXPECT_EQ(frames_[0], golden::base::kClearEncodersSeq0);  // clear, SEQ 00
  EXPECT_EQ(frames_[1], golden::base::kResetSeq1);          // Reset, SEQ 01
  port_up_ = false;
  EXPECT_FALSE(controller_.sendReset());
}

TEST_F(BaseControllerTest, StopWritesAZeroSpeedFrame) {
  command(*clock_, controller_, 0.5, 0.0);
  frames_.clear();
  controller_.stop();
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0][4], 0x01);
  for (int i = 5; i < 13; ++i) EXPECT_EQ(frames_[0][i], 0) << "byte " << i;
  ASSERT_FALSE(sent_.empty());
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
}

// --- immediate frames: spaced by the line, not by the loop --------------------------------------

// Wheel-speed frame: 14 bytes = 140 bits; at 115200 baud 1.2153 ms on the wire; at most half the
// line for such frames: one every 2.4306 ms (411 Hz).
constexpr auto kExpectedImmediateInterval = std::chrono::nanoseconds(2430556);

/// Moves the manual clock to `target`, stopping at every 20 ms tick on the way so each tick runs
/// at its own deadline (as on the real clock).
void advanceTo(core::ManualClock& clock, core::Clock::time_point t0,
               core::Clock::time_point target) {
  while (clock.now() < target) {
    const auto since_start = clock.now() - t0;
    const auto next_tick = t0 + (since_start / milliseconds(20) + 1) * milliseconds(20);
    clock.advance(std::min(next_tick, target) - clock.now());
  }
}

TEST_F(BaseControllerTest, ImmediateSpacingComesFromTheBaudRate) {
  const auto interval = controller_.minImmediateInterval();
  EXPECT_NEAR(std::chrono::duration<double>(interval).count(),
              std::chrono::duration<double>(kExpectedImmediateInterval).count(), 1e-8);
}

TEST_F(BaseControllerTest, CmdVelAt300HzGoesOutAtOnceEveryTime) {
  // 300 Hz = 3.333 ms apart, starting 2.9 ms after t0 so no command falls within the spacing
  // right after a tick (the pattern repeats every 20 ms: six commands per tick).
  const auto spacing = std::chrono::microseconds(3333);
  for (int k = 0; k < 60; ++k) {  // 0.2 s
    const core::Clock::time_point at = t0_ + std::chrono::microseconds(2900) + k * spacing;
    advanceTo(*clock_, t0_, at);
    const double speed = 0.05 + 0.005 * (k % 20);
    command(*clock_, controller_, speed, 0.0);
    ASSERT_FALSE(sent_.empty());
    EXPECT_EQ(sent_.back().time, at) << "command " << k << " was held back";
    EXPECT_NEAR(sent_.back().speeds.x(), speed, 1e-12) << "command " << k;
  }
  EXPECT_EQ(controller_.stats().immediate_frames, 60u);
}

TEST_F(BaseControllerTest, CmdVelFloodIsLimitedToTheLineShareAndTicksKeepTheirSchedule) {
  // 10 kHz for 0.2 s: 2000 commands.
  const auto spacing = std::chrono::microseconds(100);
  for (int k = 1; k <= 2000; ++k) {
    advanceTo(*clock_, t0_, t0_ + k * spacing);
    command(*clock_, controller_, 0.1 + 0.0001 * (k % 100), 0.0);
  }
  const uint64_t immediate = controller_.stats().immediate_frames;
  // 200 ms / 2.43 ms = 82.3: at most 83 rushed frames, and they did keep coming.
  EXPECT_LE(immediate, 83u);
  EXPECT_GE(immediate, 40u);
  // Any two speed frames the commands caused are at least the interval apart, and the scheduled
  // frames stayed on their 20 ms grid.
  std::optional<core::Clock::time_point> last_immediate;
  int scheduled = 0;
  for (const WheelFrameSent& sent : sent_) {
    const auto offset = sent.time - t0_;
    if (offset % milliseconds(20) == core::Clock::duration::zero()) {
      ++scheduled;
      continue;
    }
    if (last_immediate) {
      EXPECT_GE(sent.time - *last_immediate, kExpectedImmediateInterval);
    }
    last_immediate = sent.time;
  }
  EXPECT_EQ(scheduled, 10) << "one tick per 20 ms in 200 ms";
}

// --- e-stop ----------------------------------------------------------------------------------

TEST_F(BaseControllerTest, EStopZeroesAtOnceIgnoresCmdVelAndKeepsTheHeartbeat) {
  command(*clock_, controller_, 0.5, 0.0);
  clock_->tick(2);
  ASSERT_GT(sent_.back().ticks.left, 0);
  const std::size_t before = sent_.size();
  clock_->advance(milliseconds(5));
  clock_->step([&] { controller_.setEStop(true); });
  ASSERT_EQ(sent_.size(), before + 1) << "the zero frame goes out at once, not at the tick";
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_TRUE(controller_.stats().e_stop);

  controller_.setCommand(0.5, 0.0);  // ignored: does not even wake the loop
  clock_->tick(10);
  EXPECT_EQ(sent_.size(), before + 1 + 10) << "frames keep flowing while stopped";
  for (std::size_t i = before; i < sent_.size(); ++i) {
    EXPECT_EQ(sent_[i].ticks, (kinematics::WheelTicks{0, 0})) << "frame " << i;
  }
  EXPECT_EQ(controller_.stats().ignored_commands_e_stop, 1u);

  // Released: still zero (the old command is not resumed) until the next cmd_vel.
  clock_->step([&] { controller_.setEStop(false); });
  clock_->tick(2);
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_FALSE(controller_.stats().e_stop);
  clock_->advance(milliseconds(5));
  command(*clock_, controller_, 0.1, 0.0);
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{4, 4}));  // 4.07 ticks
}

// An e-stop voids everything accepted before it: the command in force is dropped when it engages
// (however short it is), and a cmd_vel accepted before it (its generation noted before the e-stop
// check) never drives after the release; only one accepted after the release does.
TEST_F(BaseControllerTest, ACmdVelAcceptedBeforeAnEStopNeverDrivesAfterTheRelease) {
  command(*clock_, controller_, 0.5, 0.0);
  clock_->tick(2);
  ASSERT_GT(sent_.back().ticks.left, 0);
  const BaseController::Generation accepted = controller_.generation();
  clock_->advance(milliseconds(5));
  // Engaged and released between two ticks.
  clock_->step([&] {
    controller_.setEStop(true);
    controller_.setEStop(false);
  });
  EXPECT_EQ(controller_.motionInForce(), "") << "the command in force was dropped";
  clock_->advance(milliseconds(5));
  // Voided: it does not even wake the loop.
  CommandOutcome outcome = controller_.submitCommand(0.5, 0.0, accepted);
  EXPECT_EQ(outcome, CommandOutcome::kVoided);
  EXPECT_EQ(controller_.stats().voided_commands, 1u);
  const std::size_t after_release = sent_.size();
  clock_->tick(10);
  for (std::size_t i = after_release; i < sent_.size(); ++i) {
    EXPECT_EQ(sent_[i].ticks, (kinematics::WheelTicks{0, 0})) << "frame " << i;
  }
  clock_->advance(milliseconds(5));
  outcome = command(*clock_, controller_, 0.1, 0.0, controller_.generation());
  EXPECT_EQ(outcome, CommandOutcome::kSent);
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{4, 4}));
}

TEST(BaseControllerEStop, StopsWithoutTheAccelerationRamp) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.max_wheel_accel = 0.5;  // m/s^2: a ramp from 0.5 m/s would take 1 s
  config.cmd_vel_timeout = 10.0;
  std::vector<WheelFrameSent> sent;
  BaseEvents events;
  events.on_wheel_frame = [&sent](const WheelFrameSent& s) { sent.push_back(s); };
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  const auto started = startOnManualClock(config, events, clock);
  BaseController& controller = *started;
  command(*clock, controller, 0.5, 0.0);
  clock->tick(100);
  ASSERT_GT(sent.back().ticks.left, 15);
  clock->advance(milliseconds(5));
  clock->step([&] { controller.setEStop(true); });
  EXPECT_EQ(sent.back().ticks, (kinematics::WheelTicks{0, 0}));
  controller.stop();
}

// What the body's gyro calibration asks: a non-zero cmd_vel in force, then the ramp down after its
// timeout, until the wheels rest; an e-stop or a zero cmd_vel holds the robot still.
TEST(BaseControllerMotion, MotionInForceNamesTheCommandThenTheRampUntilTheWheelsRest) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.max_wheel_accel = 1.0;  // 0.5 m/s takes 0.5 s to ramp down
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  auto controller = startOnManualClock(config, {}, clock);
  EXPECT_EQ(controller->motionInForce(), "") << "never commanded";
  command(*clock, *controller, 0.5, 0.0);
  EXPECT_EQ(controller->motionInForce(), "cmd_vel of 0.5 m/s, 0 rad/s in force");
  clock->tick(30);  // 600 ms: the command timed out after 0.5 s, the wheels are ramping down
  EXPECT_NE(controller->motionInForce().find("wheels still ramping"), std::string::npos)
      << controller->motionInForce();
  clock->tick(40);
  EXPECT_EQ(controller->motionInForce(), "") << "at rest";
  command(*clock, *controller, 0.0, 0.0);
  EXPECT_EQ(controller->motionInForce(), "") << "a zero cmd_vel commands stillness";
  command(*clock, *controller, 0.0, 0.3);
  EXPECT_NE(controller->motionInForce(), "");
  controller->setEStop(true);
  EXPECT_EQ(controller->motionInForce(), "") << "the e-stop holds zero at once";
  controller->stop();
}

}  // namespace
}  // namespace serial_robot_driver::devices::base
