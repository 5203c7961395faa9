// BaseController retuned while its loop runs: speed limit, geometry, timeouts, battery poll rate
// and the IMU heading switch.
#include <gtest/gtest.h>

#include "support/base_controller_fixture.h"

namespace serial_robot_driver::devices::base {
namespace {

using namespace base_controller_test;  // NOLINT: the shared fixture

// --- retune: the tunable part of the configuration changed while the loop runs ----------------

/// Sequence numbers one apart (mod 256) and no Reset after the first frame.
void expectOneUnbrokenSequence(const std::vector<WheelFrameSent>& sent) {
  for (std::size_t i = 1; i < sent.size(); ++i) {
    EXPECT_FALSE(sent[i].reset_before) << "frame " << i;
    EXPECT_EQ(sent[i].seq, static_cast<uint8_t>(sent[i - 1].seq + 1)) << "frame " << i;
  }
}

TEST_F(BaseControllerTest, RetunedSpeedLimitAppliesFromTheNextTickWithoutAReset) {
  for (int i = 0; i < 5; ++i) {
    command(*clock_, controller_, 2.0, 0.0);  // clamped to 1 m/s: ~40.7 ticks
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
    command(*clock_, controller_, 0.0, 1.0);  // -/+ 0.2 m/s at 0.40 m
    clock_->tick(1);
  }
  const double yaw_before = odometry_.back().pose.yaw;
  EXPECT_NEAR(odometry_.back().angular, 1.0, 0.05);
  BaseConfig wider = controller_.config();
  wider.geometry.wheel_separation = 0.80;
  controller_.retune(wider);
  for (int i = 0; i < 10; ++i) {
    command(*clock_, controller_, 0.0, 1.0);  // now -/+ 0.4 m/s
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
  command(*clock_, controller_, 0.2, 0.0);
  clock_->tick(4);  // 80 ms: still driving
  EXPECT_GT(sent_.back().ticks.left, 0);
  clock_->tick(2);  // 120 ms: the 0.1 s timeout (not the 0.5 s one it started with) has passed
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 1u);
}

TEST_F(BaseControllerTest, RetunedWheelDiameterChangesTheTicksAndKeepsTheWheelAngles) {
  for (int i = 0; i < 10; ++i) {
    command(*clock_, controller_, 0.2, 0.0);  // ~8.1 ticks with 0.25 m wheels
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

// retune() takes the BaseTuning part over whole (the rows of every tunable bind there) and keeps
// the rest of the configuration it was built with.
TEST_F(BaseControllerTest, RetuneTakesTheTuningPartWholeAndKeepsTheRest) {
  BaseConfig next = controller_.config();
  next.geometry.wheel_diameter = 0.3;
  next.geometry.wheel_separation = 0.5;
  next.max_wheel_speed = 0.7;
  next.max_wheel_accel = 2.0;
  next.cmd_vel_timeout = 0.3;
  next.speed_dithering = !next.speed_dithering;
  next.battery_poll_rate = 2.0;
  next.use_imu_heading = !next.use_imu_heading;
  next.loop_rate = 10.0;  // not tunable: it needs a new controller
  next.left_wheel_direction = -1;
  const BaseConfig before = controller_.config();
  controller_.retune(next);
  const BaseConfig now = controller_.config();
  EXPECT_EQ(now.geometry.wheel_diameter, 0.3);
  EXPECT_EQ(now.geometry.wheel_separation, 0.5);
  EXPECT_EQ(now.max_wheel_speed, 0.7);
  EXPECT_EQ(now.max_wheel_accel, 2.0);
  EXPECT_EQ(now.cmd_vel_timeout, 0.3);
  EXPECT_EQ(now.speed_dithering, next.speed_dithering);
  EXPECT_EQ(now.battery_poll_rate, 2.0);
  EXPECT_EQ(now.use_imu_heading, next.use_imu_heading);
  EXPECT_EQ(now.loop_rate, before.loop_rate);
  EXPECT_EQ(now.left_wheel_direction, before.left_wheel_direction);
}

TEST(BaseControllerRetune, FasterBatteryPollStartsWithoutWaitingForTheSlowPeriod) {
  BaseConfig config;
  config.battery_poll_rate = 0.2;  // every 5 s
  std::vector<Bytes> frames;
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
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
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  auto controller = startOnManualClock(config, events, clock);
  double imu_yaw = 2.0;  // far from odom's heading: fusion must anchor, not jump to it
  const auto feed = [&] { controller->onImuYaw(imu_yaw, clock->now()); };
  command(*clock, *controller, 0.0, 0.5);
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
}  // namespace serial_robot_driver::devices::base
