// BaseController: the Reset/heartbeat cycle, cmd_vel handling and battery polling, driven by a
// manual clock (the loop thread runs; the test moves time) and a fake port that records every
// frame; two tests run the loop on the real clock.
#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "serial_robot_driver/device/base_controller.h"
#include "support/golden_frames.h"
#include "support/manual_clock.h"

namespace serial_robot_driver::device {
namespace {

using Bytes = std::vector<uint8_t>;
using std::chrono::milliseconds;

/// A controller whose loop runs on `clock`, started and waiting for its first tick; the frames it
/// writes go to `frames` when one is given (for tests with a configuration of their own).
std::unique_ptr<BaseController> startOnManualClock(const BaseConfig& config, BaseEvents events,
                                                   const std::shared_ptr<ManualClock>& clock,
                                                   std::vector<Bytes>* frames = nullptr) {
  auto controller = std::make_unique<BaseController>(
      config,
      [frames](const Bytes& frame) {
        if (frames != nullptr) frames->push_back(frame);
        return true;
      },
      std::move(events), clock);
  controller->start();
  clock->waitForLoop();
  return controller;
}

/// The controller's loop runs at 50 Hz on a ManualClock that starts at t0: the first tick falls
/// due at t0 + 20 ms.
class BaseControllerTest : public ::testing::Test {
 protected:
  BaseControllerTest()
      : clock_(std::make_shared<ManualClock>(t0_)),
        controller_(config(), [this](const Bytes& frame) { return write(frame); }, events(), clock_) {
    controller_.start();
    clock_->waitForLoop();
  }

  BaseEvents events() {
    BaseEvents events;
    events.on_wheel_frame = [this](const WheelFrameSent& sent) { sent_.push_back(sent); };
    events.on_odometry = [this](const OdometrySample& sample) { odometry_.push_back(sample); };
    return events;
  }

  static BaseConfig config() {
    BaseConfig c;
    c.battery_poll_rate = 0;  // tests that want polling enable it on their own controller
    return c;
  }

  // Called on the loop thread while the test waits in a ManualClock step, or on the test thread
  // while the loop waits: the clock's mutex orders the two.
  bool write(const Bytes& frame) {
    if (!port_up_) return false;
    frames_.push_back(frame);
    return true;
  }

  // Declared before the controller, so they outlive its loop thread.
  std::vector<Bytes> frames_;
  std::vector<WheelFrameSent> sent_;
  std::vector<OdometrySample> odometry_;
  bool port_up_ = true;
  const Clock::time_point t0_ = Clock::now();
  std::shared_ptr<ManualClock> clock_;
  BaseController controller_;
};

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
  clock_->step([&] { controller_.setCommand(0.1, 0.0); });
  ASSERT_EQ(frames_.size(), 2u) << "sent before the first tick is due";
  // 0.1 m/s = 4.07 ticks per period -> 4 on the first frame; SEQ 01: XOR = F7 ^ 01 = F6
  EXPECT_EQ(frames_[1], golden::base::kBoth4Seq1);
  EXPECT_EQ(controller_.stats().immediate_frames, 1u);
}

TEST_F(BaseControllerTest, TurnInPlaceGivesOppositeTicks) {
  clock_->step([&] { controller_.setCommand(0.0, 1.0); });  // wheels at -/+ 0.2 m/s
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_LT(sent_[0].ticks.left, 0);
  EXPECT_EQ(sent_[0].ticks.left, -sent_[0].ticks.right);
  EXPECT_EQ(sent_[0].ticks.right, 8);
}

TEST_F(BaseControllerTest, HugeCommandKeepsItsDirectionAtFullSpeed) {
  clock_->step([&] { controller_.setCommand(1e308, 1e308); });  // the wheel sum would overflow to inf
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_NEAR(sent_[0].speeds.y(), 1.0, 1e-9) << "the faster wheel at max_wheel_speed";
  EXPECT_GT(sent_[0].speeds.x(), 0.0);
  EXPECT_LT(sent_[0].speeds.x(), 1.0);
  EXPECT_EQ(sent_[0].ticks.right, 41);  // 40.74 ticks per period, rounded on the first frame
}

TEST_F(BaseControllerTest, CommandTimesOutToZero) {
  clock_->step([&] { controller_.setCommand(0.5, 0.0); });
  ASSERT_GT(sent_.back().ticks.left, 0);
  clock_->tick(24);  // 480 ms: cmd_vel_timeout is 0.5 s
  EXPECT_GT(sent_.back().ticks.left, 0);
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 0u);
  clock_->tick(6);  // 600 ms
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 1u);
}

TEST_F(BaseControllerTest, NonFiniteCommandIsRejectedAsZero) {
  clock_->step([&] {
    controller_.setCommand(0.5, 0.0);
    EXPECT_FALSE(controller_.setCommand(std::nan(""), 0.0));
    EXPECT_FALSE(controller_.setCommand(0.1, INFINITY));
  });
  clock_->tick(1);  // the latest command goes out by the next tick at the latest
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().rejected_commands, 2u);
}

TEST_F(BaseControllerTest, TimeoutErrorFrameMakesNextFrameReset) {
  clock_->tick(2);
  frames_.clear();
  // FF error status from the base, SEQ 07: 55^AA^02^07^FF^00 = 05
  const Bytes& error = golden::base::kErrorStatusSeq7;
  clock_->step([&] {
    controller_.onFrame(protocol::base::kFrames, error.data(), error.size(), clock_->now());
  });
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
  EXPECT_EQ(frames_[1], golden::base::kResetSeq1);  // Reset, SEQ 01
  port_up_ = false;
  EXPECT_FALSE(controller_.sendReset());
}

TEST_F(BaseControllerTest, StopWritesAZeroSpeedFrame) {
  clock_->step([&] { controller_.setCommand(0.5, 0.0); });
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
void advanceTo(ManualClock& clock, Clock::time_point t0, Clock::time_point target) {
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
    const Clock::time_point at = t0_ + std::chrono::microseconds(2900) + k * spacing;
    advanceTo(*clock_, t0_, at);
    const double speed = 0.05 + 0.005 * (k % 20);
    clock_->step([&] { controller_.setCommand(speed, 0.0); });
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
    clock_->step([&] { controller_.setCommand(0.1 + 0.0001 * (k % 100), 0.0); });
  }
  const uint64_t immediate = controller_.stats().immediate_frames;
  // 200 ms / 2.43 ms = 82.3: at most 83 rushed frames, and they did keep coming.
  EXPECT_LE(immediate, 83u);
  EXPECT_GE(immediate, 40u);
  // Any two speed frames the commands caused are at least the interval apart, and the scheduled
  // frames stayed on their 20 ms grid.
  std::optional<Clock::time_point> last_immediate;
  int scheduled = 0;
  for (const WheelFrameSent& sent : sent_) {
    const auto offset = sent.time - t0_;
    if (offset % milliseconds(20) == Clock::duration::zero()) {
      ++scheduled;
      continue;
    }
    if (last_immediate) EXPECT_GE(sent.time - *last_immediate, kExpectedImmediateInterval);
    last_immediate = sent.time;
  }
  EXPECT_EQ(scheduled, 10) << "one tick per 20 ms in 200 ms";
}

// --- e-stop ----------------------------------------------------------------------------------

TEST_F(BaseControllerTest, EStopZeroesAtOnceIgnoresCmdVelAndKeepsTheHeartbeat) {
  clock_->step([&] { controller_.setCommand(0.5, 0.0); });
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
  clock_->step([&] { controller_.setCommand(0.1, 0.0); });
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{4, 4}));  // 4.07 ticks
}

TEST(BaseControllerEStop, StopsWithoutTheAccelerationRamp) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.max_wheel_accel = 0.5;  // m/s^2: a ramp from 0.5 m/s would take 1 s
  config.cmd_vel_timeout = 10.0;
  std::vector<WheelFrameSent> sent;
  BaseEvents events;
  events.on_wheel_frame = [&sent](const WheelFrameSent& s) { sent.push_back(s); };
  auto clock = std::make_shared<ManualClock>(Clock::now());
  const auto started = startOnManualClock(config, events, clock);
  BaseController& controller = *started;
  clock->step([&] { controller.setCommand(0.5, 0.0); });
  clock->tick(100);
  ASSERT_GT(sent.back().ticks.left, 15);
  clock->advance(milliseconds(5));
  clock->step([&] { controller.setEStop(true); });
  EXPECT_EQ(sent.back().ticks, (kinematics::WheelTicks{0, 0}));
  controller.stop();
}

// --- odometry from the accepted frames -------------------------------------------------------

TEST_F(BaseControllerTest, OdometryIntegratesTheTicksSent) {
  // 8 ticks per period exactly: 8 / 40.7437 = 0.19635 m/s on both wheels.
  const double per_tick = 1.0 / kinematics::DiffDriveGeometry{}.ticksPerPeriodPerMps();
  const double speed = 8 * per_tick;
  clock_->step([&] { controller_.setCommand(speed, 0.0); });  // at t0, Reset + frame
  for (int i = 0; i < 20; ++i) {
    clock_->step([&] { controller_.setCommand(speed, 0.0); });
    clock_->tick(1);
  }
  ASSERT_FALSE(odometry_.empty());
  for (const WheelFrameSent& s : sent_) EXPECT_EQ(s.ticks, (kinematics::WheelTicks{8, 8}));
  // 20 ticks = 0.4 s at 0.19635 m/s.
  EXPECT_NEAR(odometry_.back().pose.x, speed * 0.4, 1e-9);
  EXPECT_NEAR(odometry_.back().pose.y, 0.0, 1e-12);
  EXPECT_NEAR(odometry_.back().linear, speed, 1e-12);
  EXPECT_EQ(odometry_.back().time, t0_ + milliseconds(400));
  EXPECT_GT(odometry_.back().position_variance, odometry_.front().position_variance);

  controller_.resetOdometry();
  clock_->tick(1);
  EXPECT_NEAR(odometry_.back().pose.x, speed * 0.02, 1e-9) << "one period since the reset";
}

TEST_F(BaseControllerTest, OdometryUsesTheRobotsTicksNotTheWheelDirections) {
  // The fixture's base has both directions 1; a base with a flipped left wheel is checked in
  // BaseControllerDirections. Here: turning on the spot turns the pose.
  clock_->step([&] { controller_.setCommand(0.0, 1.0); });  // -/+ 8 ticks
  clock_->tick(50);  // 1 s, but cmd_vel_timeout stops it after 0.5 s
  EXPECT_GT(odometry_.back().pose.yaw, 0.3);
  EXPECT_NEAR(odometry_.back().pose.x, 0.0, 1e-9);
}

TEST_F(BaseControllerTest, WheelTravelFollowsTheAcceptedTicksAndSurvivesAnOdometryReset) {
  // Turning on the spot: -8 / +8 ticks per period, so the wheels travel opposite ways.
  const double per_tick = 1.0 / kinematics::DiffDriveGeometry{}.ticksPerPeriodPerMps();
  for (int i = 0; i < 10; ++i) {
    clock_->step([&] { controller_.setCommand(0.0, 1.0); });
    clock_->tick(1);
  }
  ASSERT_EQ(sent_.back().ticks, (kinematics::WheelTicks{-8, 8}));
  const OdometrySample driven = odometry_.back();  // a copy: more samples follow
  EXPECT_NEAR(driven.wheel_speeds.x(), -8 * per_tick, 1e-12);
  EXPECT_NEAR(driven.wheel_speeds.y(), 8 * per_tick, 1e-12);
  // The same motion as the pose: each wheel's path is the distance odometry counted.
  EXPECT_GT(driven.travelled, 8 * per_tick * 0.15);
  EXPECT_NEAR(driven.wheel_travel.x(), -driven.travelled, 1e-9);
  EXPECT_NEAR(driven.wheel_travel.y(), driven.travelled, 1e-9);
  // Half the distance between the wheels' paths over the separation is the heading.
  EXPECT_NEAR((driven.wheel_travel.y() - driven.wheel_travel.x()) /
                  kinematics::DiffDriveGeometry{}.wheel_separation,
              driven.pose.yaw, 1e-9);

  const Eigen::Vector2d before_reset = odometry_.back().wheel_travel;
  controller_.resetOdometry();
  clock_->tick(1);
  EXPECT_LT(odometry_.back().pose.yaw, driven.pose.yaw / 5) << "the pose starts again";
  EXPECT_GT(odometry_.back().wheel_travel.y(), before_reset.y()) << "wheel angles do not jump back";
}

TEST_F(BaseControllerTest, PortDownStopsIntegratingAfterTheBasesOwnTimeout) {
  const double per_tick = 1.0 / kinematics::DiffDriveGeometry{}.ticksPerPeriodPerMps();
  const double speed = 8 * per_tick;
  for (int i = 0; i < 10; ++i) {  // 200 ms of driving
    clock_->step([&] { controller_.setCommand(speed, 0.0); });
    clock_->tick(1);
  }
  // The port goes away: nothing more reaches the base, which runs on until its 1 s timeout.
  port_up_ = false;
  controller_.onLinkDown();
  for (int i = 0; i < 150; ++i) {  // 3 s of commands that never reach the wheels
    clock_->step([&] { controller_.setCommand(speed, 0.0); });
    clock_->tick(1);
  }
  EXPECT_NEAR(odometry_.back().pose.x, speed * (0.2 + 1.0), 1e-9);
  EXPECT_NEAR(odometry_.back().linear, 0.0, 1e-12) << "the base has stopped";
}

TEST(BaseControllerDirections, FlippedWheelNegatesItsTicksOnTheWireOnly) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.left_wheel_direction = -1;
  std::vector<Bytes> frames;
  std::vector<OdometrySample> samples;
  BaseEvents events;
  events.on_odometry = [&samples](const OdometrySample& s) { samples.push_back(s); };
  auto clock = std::make_shared<ManualClock>(Clock::now());
  const auto started = startOnManualClock(config, events, clock, &frames);
  BaseController& controller = *started;
  clock->step([&] { controller.setCommand(0.1, 0.0); });
  // 0.1 m/s = 4.07 -> 4 ticks; left flipped: FF FC, right 00 04; XOR 55^AA^09^01^01^FF^FC^04 = F1
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1],
            golden::base::kLeftMinus4Right4Seq1);
  clock->tick(1);
  ASSERT_FALSE(samples.empty());
  EXPECT_GT(samples.back().pose.x, 0.0) << "the robot drives forward whatever the wire says";
  EXPECT_NEAR(samples.back().angular, 0.0, 1e-12);
  controller.stop();
}

// --- the base going silent -------------------------------------------------------------------

TEST(BaseControllerSilence, UnansweredPollsMakeTheBaseSilentOnceUntilItAnswers) {
  BaseConfig config;
  config.battery_poll_rate = 1.0;
  int silent_events = 0;
  BaseEvents events;
  events.on_silent = [&silent_events](double) { ++silent_events; };
  auto clock = std::make_shared<ManualClock>(Clock::now());
  const auto started = startOnManualClock(config, events, clock);
  BaseController& controller = *started;
  clock->tick(150);  // 3 s: the first request went out at 1.02 s (the first tick sent the Reset)
  EXPECT_FALSE(controller.stats().base_silent);
  ASSERT_TRUE(controller.stats().seconds_without_reply.has_value());
  clock->tick(100);  // 5 s: more than 3 poll periods without a reply
  EXPECT_TRUE(controller.stats().base_silent);
  EXPECT_GT(*controller.stats().seconds_without_reply, 3.0);
  clock->tick(100);
  EXPECT_EQ(silent_events, 1) << "reported once, not every tick";
  // battery reply, 87 %, SEQ 00: 55^AA^02^00^02^57 = A8
  const Bytes& reply = golden::base::kBattery87ReplySeq0;
  controller.onFrame(protocol::base::kFrames, reply.data(), reply.size(), clock->now());
  EXPECT_FALSE(controller.stats().base_silent);
  controller.stop();
}

TEST_F(BaseControllerTest, TimeoutErrorWhileRunningIsCountedButNotTheOneAtStart) {
  // FF error status from the base, SEQ 07: 55^AA^02^07^FF^00 = 05
  const Bytes& error = golden::base::kErrorStatusSeq7;
  clock_->tick(1);  // Reset + first frame
  clock_->step([&] {
    controller_.onFrame(protocol::base::kFrames, error.data(), error.size(), clock_->now());
  });
  EXPECT_EQ(controller_.stats().timeout_errors_while_running, 0u) << "in flight before our Reset";
  clock_->tick(100);  // 2 s of running
  clock_->step([&] {
    controller_.onFrame(protocol::base::kFrames, error.data(), error.size(), clock_->now());
  });
  EXPECT_EQ(controller_.stats().timeout_errors_while_running, 1u);
  ASSERT_TRUE(controller_.stats().seconds_since_running_timeout_error.has_value());
  EXPECT_EQ(controller_.stats().timeout_errors_received, 2u);
}

TEST(BaseControllerBattery, PollsAtTheConfiguredRateAndReportsReplies) {
  BaseConfig config;
  config.battery_poll_rate = 1.0;
  std::vector<Bytes> frames;
  std::vector<int> percents;
  BaseEvents events;
  events.on_battery = [&percents](uint8_t p, Clock::time_point) { percents.push_back(p); };
  auto clock = std::make_shared<ManualClock>(Clock::now());
  const auto started = startOnManualClock(config, events, clock, &frames);
  BaseController& controller = *started;
  clock->tick(101);  // 2.02 s: the first tick sends the Reset instead, then one request per second
  int requests = 0;
  for (const Bytes& f : frames) requests += (f[4] == 0x02);
  EXPECT_EQ(requests, 2);
  EXPECT_EQ(controller.stats().battery_requests, 2u);
  // battery reply, 87 %, SEQ 00: 55^AA^02^00^02^57 = A8
  const Bytes& reply = golden::base::kBattery87ReplySeq0;
  controller.onFrame(protocol::base::kFrames, reply.data(), reply.size(), Clock::now());
  ASSERT_EQ(percents.size(), 1u);
  EXPECT_EQ(percents[0], 87);
  controller.stop();
}

class RecordingWriter {
 public:
  bool operator()(const Bytes& frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    frames_.push_back(frame);
    return true;
  }
  std::vector<Bytes> frames() {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }

 private:
  std::mutex mutex_;
  std::vector<Bytes> frames_;
};

TEST(BaseControllerLoop, RunningLoopKeepsTheHeartbeatAndStopsTheWheels) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  RecordingWriter writer;
  BaseController controller(config, std::ref(writer));
  controller.start();
  controller.setCommand(0.2, 0.0);
  std::this_thread::sleep_for(milliseconds(300));
  controller.stop();
  const std::vector<Bytes> frames = writer.frames();
  ASSERT_GE(frames.size(), 5u) << "about 15 ticks in 300 ms at 50 Hz";
  EXPECT_EQ(frames.front()[4], 0x05);
  bool moved = false;
  for (const Bytes& f : frames) moved |= (f[4] == 0x01 && f[6] > 0);
  EXPECT_TRUE(moved);
  EXPECT_EQ(frames.back()[4], 0x01);
  EXPECT_EQ(frames.back()[6], 0) << "the last frame stops the wheels";
}

TEST(BaseControllerLoop, NewCommandGoesOutBeforeTheNextTick) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.loop_rate = 0.5;  // the first tick is 2 s away: only a rushed frame can appear before it
  RecordingWriter writer;
  BaseController controller(config, std::ref(writer));
  controller.start();
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_TRUE(writer.frames().empty());
  controller.setCommand(0.2, 0.0);
  const auto deadline = Clock::now() + milliseconds(1500);
  while (writer.frames().size() < 2 && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(2));
  }
  const std::vector<Bytes> frames = writer.frames();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0][4], 0x05) << "Reset first";
  EXPECT_EQ(frames[1][4], 0x01);
  EXPECT_EQ(frames[1][6], 8) << "0.2 m/s = 8.15 ticks per period";
  EXPECT_EQ(controller.stats().immediate_frames, 1u);
  controller.stop();
}

}  // namespace
}  // namespace serial_robot_driver::device

// --- the IMU's heading in the odometry (use_imu_heading) -------------------------------------

namespace serial_robot_driver::device {
namespace {

TEST(BaseControllerImuHeading, FollowsTheImuFallsBackWithoutAJumpAndResumesWithoutOne) {
  std::vector<OdometrySample> odometry;
  std::vector<kinematics::HeadingSource> sources;
  BaseEvents events;
  events.on_odometry = [&](const OdometrySample& sample) { odometry.push_back(sample); };
  events.on_heading_source = [&](kinematics::HeadingSource s) { sources.push_back(s); };
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.cmd_vel_timeout = 100;  // one command turns for the whole test
  config.use_imu_heading = true;
  config.imu_yaw_variance = 0.0003;
  const Clock::time_point t0 = Clock::now();
  auto clock = std::make_shared<ManualClock>(t0);
  auto controller = startOnManualClock(config, events, clock);

  // The IMU starts at an arbitrary yaw (2.0 rad): odom's heading is relative to it.
  double imu_yaw = 2.0;
  const auto feed = [&] { controller->onImuYaw(imu_yaw, clock->now()); };
  feed();
  clock->tick(1);
  ASSERT_FALSE(odometry.empty());
  EXPECT_TRUE(odometry.back().imu_heading);
  EXPECT_NEAR(odometry.back().pose.yaw, 0.0, 1e-12);
  ASSERT_EQ(sources, std::vector<kinematics::HeadingSource>{kinematics::HeadingSource::kImu});

  // Commanded 0.5 rad/s; the IMU says the base turns at 0.35 rad/s (slip): odom follows the IMU.
  clock->step([&] { controller->setCommand(0.0, 0.5); });
  for (int i = 0; i < 50; ++i) {
    imu_yaw += 0.35 * 0.02;
    feed();
    clock->tick(1);
  }
  EXPECT_NEAR(odometry.back().pose.yaw, 0.35, 1e-9);
  EXPECT_NEAR(odometry.back().yaw_variance, 0.0003, 1e-12);
  EXPECT_NEAR(odometry.back().pose.x, 0.0, 1e-9) << "turning on the spot";

  // The IMU goes quiet: after 0.25 s odom integrates the commanded turn from the fused heading.
  const std::size_t before_outage = odometry.size();
  clock->tick(40);  // 0.8 s
  EXPECT_FALSE(odometry.back().imu_heading);
  ASSERT_EQ(sources.size(), 2u);
  EXPECT_EQ(sources.back(), kinematics::HeadingSource::kImuStale);
  EXPECT_GT(odometry.back().pose.yaw, 0.35 + 0.2) << "the commanded turn goes on";
  EXPECT_GT(odometry.back().yaw_variance, 0.0003) << "and the yaw variance grows again";
  EXPECT_EQ(controller->stats().imu_heading_fallbacks, 1u);
  // The IMU returns at a yaw far from where odom stands: odom carries on from its own heading.
  imu_yaw = -3.0;
  feed();
  clock->tick(1);
  const double resumed_at = odometry.back().pose.yaw;
  EXPECT_TRUE(odometry.back().imu_heading);
  for (int i = 0; i < 10; ++i) {
    imu_yaw += 0.35 * 0.02;
    feed();
    clock->tick(1);
  }
  EXPECT_NEAR(odometry.back().pose.yaw, resumed_at + 0.07, 1e-9);
  // No jump anywhere: no step turned more than the commanded 0.5 rad/s allows in one period
  // (0.01 rad; 0.0123 when dithering puts a fifth tick on each wheel).
  for (std::size_t i = before_outage; i < odometry.size(); ++i) {
    const double step = std::remainder(odometry[i].pose.yaw - odometry[i - 1].pose.yaw, 2 * M_PI);
    EXPECT_LE(std::abs(step), 0.015) << "step " << i;
  }

  // base/reset_odometry: the fused heading restarts at zero where the IMU stands now.
  controller->resetOdometry();
  imu_yaw += 0.05;
  feed();
  clock->tick(1);
  EXPECT_NEAR(odometry.back().pose.yaw, 0.05, 1e-9);
  EXPECT_NEAR(odometry.back().yaw_variance, 0.0003, 1e-12);
  controller->stop();
}

}  // namespace
}  // namespace serial_robot_driver::device

// --- retune: the tunable part of the configuration changed while the loop runs ----------------
namespace serial_robot_driver::device {
namespace {

/// Sequence numbers one apart (mod 256) and no Reset after the first frame.
void expectOneUnbrokenSequence(const std::vector<WheelFrameSent>& sent) {
  for (std::size_t i = 1; i < sent.size(); ++i) {
    EXPECT_FALSE(sent[i].reset_before) << "frame " << i;
    EXPECT_EQ(sent[i].seq, static_cast<uint8_t>(sent[i - 1].seq + 1)) << "frame " << i;
  }
}

TEST_F(BaseControllerTest, RetunedSpeedLimitAppliesFromTheNextTickWithoutAReset) {
  for (int i = 0; i < 5; ++i) {
    clock_->step([&] { controller_.setCommand(2.0, 0.0); });  // clamped to 1 m/s: ~40.7 ticks
    clock_->tick(1);
  }
  EXPECT_NEAR(sent_.back().ticks.left, 40.7, 1.0);
  BaseConfig slower = controller_.config();
  slower.max_wheel_speed = 0.5;
  controller_.retune(slower);
  const std::size_t before = sent_.size();
  clock_->tick(1);  // no new cmd_vel: the next tick already obeys the new limit
  ASSERT_EQ(sent_.size(), before + 1);
  EXPECT_NEAR(sent_.back().ticks.left, 20.4, 1.0);
  EXPECT_EQ(sent_.back().ticks.left, sent_.back().ticks.right);
  EXPECT_NEAR(sent_.back().speeds.x(), 0.5, 1e-9);
  expectOneUnbrokenSequence(sent_);
  EXPECT_EQ(controller_.stats().resets_sent, 1u);
  EXPECT_DOUBLE_EQ(controller_.config().max_wheel_speed, 0.5);
}

TEST_F(BaseControllerTest, RetunedWheelSeparationKeepsThePoseAndTurnsAtTheCommandedRate) {
  for (int i = 0; i < 10; ++i) {
    clock_->step([&] { controller_.setCommand(0.0, 1.0); });  // -/+ 0.2 m/s at 0.40 m
    clock_->tick(1);
  }
  const double yaw_before = odometry_.back().pose.yaw;
  EXPECT_NEAR(odometry_.back().angular, 1.0, 0.05);
  BaseConfig wider = controller_.config();
  wider.geometry.wheel_separation = 0.80;
  controller_.retune(wider);
  for (int i = 0; i < 10; ++i) {
    clock_->step([&] { controller_.setCommand(0.0, 1.0); });  // now -/+ 0.4 m/s
    clock_->tick(1);
  }
  const OdometrySample after = odometry_.back();
  EXPECT_NEAR(after.wheel_speeds.y(), 0.4, 0.03);
  EXPECT_NEAR(after.wheel_speeds.x(), -0.4, 0.03);
  // Odometry turns with the new separation: the wheel speeds over 0.80 m are the commanded rate.
  EXPECT_NEAR(after.angular, 1.0, 0.05);
  EXPECT_NEAR((after.wheel_speeds.y() - after.wheel_speeds.x()) / 0.80, after.angular, 1e-9);
  // The pose went on from where it was: ten more periods at about 1 rad/s.
  EXPECT_NEAR(after.pose.yaw - yaw_before, 0.2, 0.02);
  expectOneUnbrokenSequence(sent_);
}

TEST_F(BaseControllerTest, ShortenedCmdVelTimeoutStopsTheWheelsSooner) {
  BaseConfig impatient = controller_.config();
  impatient.cmd_vel_timeout = 0.1;
  controller_.retune(impatient);
  clock_->step([&] { controller_.setCommand(0.2, 0.0); });
  clock_->tick(4);  // 80 ms: still driving
  EXPECT_GT(sent_.back().ticks.left, 0);
  clock_->tick(2);  // 120 ms: the 0.1 s timeout (not the 0.5 s one it started with) has passed
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 1u);
}

TEST_F(BaseControllerTest, RetunedWheelDiameterChangesTheTicksAndKeepsTheWheelAngles) {
  for (int i = 0; i < 10; ++i) {
    clock_->step([&] { controller_.setCommand(0.2, 0.0); });  // ~8.1 ticks with 0.25 m wheels
    clock_->tick(1);
  }
  const OdometrySample before = odometry_.back();
  EXPECT_NEAR(before.wheel_angles.x(), before.wheel_travel.x() / 0.125, 1e-9);
  BaseConfig bigger = controller_.config();
  bigger.geometry.wheel_diameter = 0.50;
  controller_.retune(bigger);
  clock_->tick(1);
  const OdometrySample after = odometry_.back();
  // Half the ticks for the same speed; the angle moved on by one period, it did not jump.
  EXPECT_NEAR(sent_.back().ticks.left, 4.07, 1.0);
  EXPECT_NEAR(after.wheel_angles.x() - before.wheel_angles.x(), 0.2 * 0.02 / 0.25, 0.02);
  EXPECT_NEAR(after.wheel_rates.x(), after.wheel_speeds.x() / 0.25, 1e-9);
  EXPECT_GT(after.pose.x, before.pose.x);
  expectOneUnbrokenSequence(sent_);
}

TEST(BaseControllerRetune, FasterBatteryPollStartsWithoutWaitingForTheSlowPeriod) {
  BaseConfig config;
  config.battery_poll_rate = 0.2;  // every 5 s
  std::vector<Bytes> frames;
  auto clock = std::make_shared<ManualClock>(Clock::now());
  const auto started = startOnManualClock(config, {}, clock, &frames);
  BaseController& controller = *started;
  clock->tick(2);  // the first tick's Reset took the request's turn: the next is 5 s away
  EXPECT_EQ(controller.stats().battery_requests, 0u);
  BaseConfig faster = controller.config();
  faster.battery_poll_rate = 10.0;
  controller.retune(faster);
  clock->tick(50);  // 1 s at 10 Hz, starting within 0.1 s
  EXPECT_GE(controller.stats().battery_requests, 9u);
  EXPECT_LE(controller.stats().battery_requests, 11u);
  faster.battery_poll_rate = 0.0;
  controller.retune(faster);
  const uint64_t requests = controller.stats().battery_requests;
  clock->tick(50);
  EXPECT_EQ(controller.stats().battery_requests, requests) << "rate 0: never ask";
  EXPECT_FALSE(controller.stats().seconds_without_reply.has_value());
  controller.stop();
}


TEST(BaseControllerRetune, ImuHeadingSwitchedOnAndOffWithoutAJump) {
  std::vector<OdometrySample> odometry;
  BaseEvents events;
  events.on_odometry = [&](const OdometrySample& sample) { odometry.push_back(sample); };
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.cmd_vel_timeout = 100;  // one command turns for the whole test
  auto clock = std::make_shared<ManualClock>(Clock::now());
  auto controller = startOnManualClock(config, events, clock);
  double imu_yaw = 2.0;  // far from odom's heading: fusion must anchor, not jump to it
  const auto feed = [&] { controller->onImuYaw(imu_yaw, clock->now()); };
  clock->step([&] { controller->setCommand(0.0, 0.5); });
  for (int i = 0; i < 20; ++i) {
    imu_yaw += 0.35 * 0.02;  // the IMU says 0.35 rad/s
    feed();
    clock->tick(1);
  }
  EXPECT_FALSE(odometry.back().imu_heading) << "off as started";
  const double commanded = odometry.back().pose.yaw;
  EXPECT_NEAR(commanded, 0.2, 0.03);  // 0.5 rad/s for 0.4 s

  BaseConfig fused = controller->config();
  fused.use_imu_heading = true;
  controller->retune(fused);
  for (int i = 0; i < 20; ++i) {
    imu_yaw += 0.35 * 0.02;
    feed();
    clock->tick(1);
  }
  EXPECT_TRUE(odometry.back().imu_heading);
  // From where odom stood, at the IMU's rate: 0.4 s at 0.35 rad/s (within one period's turn).
  EXPECT_NEAR(odometry.back().pose.yaw - commanded, 0.14, 0.011);

  const double fused_yaw = odometry.back().pose.yaw;
  fused.use_imu_heading = false;
  controller->retune(fused);
  clock->tick(1);
  EXPECT_FALSE(odometry.back().imu_heading);
  EXPECT_NEAR(odometry.back().pose.yaw - fused_yaw, 0.01, 0.003) << "the commanded turn goes on";
  controller->stop();
}

}  // namespace
}  // namespace serial_robot_driver::device
