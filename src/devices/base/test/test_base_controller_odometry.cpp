// BaseController's odometry: integrated from the accepted ticks, wheel travel, a port that went
// down, flipped wheels and the IMU's heading.
#include <gtest/gtest.h>

#include "support/base_controller_fixture.h"

namespace serial_robot_driver::devices::base {
namespace {

using namespace base_controller_test;  // NOLINT: the shared fixture

// --- odometry from the accepted frames -------------------------------------------------------

TEST_F(BaseControllerTest, OdometryIntegratesTheTicksSent) {
  // 8 ticks per period exactly: 8 / 40.7437 = 0.19635 m/s on both wheels.
  const double per_tick = 1.0 / kinematics::DiffDriveGeometry{}.ticksPerPeriodPerMps();
  const double speed = 8 * per_tick;
  command(*clock_, controller_, speed, 0.0);  // at t0, Reset + frame
  for (int i = 0; i < 20; ++i) {
    command(*clock_, controller_, speed, 0.0);
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
  command(*clock_, controller_, 0.0, 1.0);  // -/+ 8 ticks
  clock_->tick(50);  // 1 s, but cmd_vel_timeout stops it after 0.5 s
  EXPECT_GT(odometry_.back().pose.yaw, 0.3);
  EXPECT_NEAR(odometry_.back().pose.x, 0.0, 1e-9);
}

TEST_F(BaseControllerTest, WheelTravelFollowsTheAcceptedTicksAndSurvivesAnOdometryReset) {
  // Turning on the spot: -8 / +8 ticks per period, so the wheels travel opposite ways.
  const double per_tick = 1.0 / kinematics::DiffDriveGeometry{}.ticksPerPeriodPerMps();
  for (int i = 0; i < 10; ++i) {
    command(*clock_, controller_, 0.0, 1.0);
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
    command(*clock_, controller_, speed, 0.0);
    clock_->tick(1);
  }
  // The port goes away: nothing more reaches the base, which runs on until its 1 s timeout.
  port_up_ = false;
  controller_.onLinkDown();
  for (int i = 0; i < 150; ++i) {  // 3 s of commands that never reach the wheels
    command(*clock_, controller_, speed, 0.0);
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
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  const auto started = startOnManualClock(config, events, clock, &frames);
  BaseController& controller = *started;
  command(*clock, controller, 0.1, 0.0);
  // 0.1 m/s = 4.07 -> 4 ticks; left flipped: FF FC, right 00 04; XOR 55^AA^09^01^01^FF^FC^04 = F1
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1], golden::base::kLeftMinus4Right4Seq1);
  clock->tick(1);
  ASSERT_FALSE(samples.empty());
  EXPECT_GT(samples.back().pose.x, 0.0) << "the robot drives forward whatever the wire says";
  EXPECT_NEAR(samples.back().angular, 0.0, 1e-12);
  controller.stop();
}

// --- the IMU's heading in the odometry (use_imu_heading) -------------------------------------

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
  const core::Clock::time_point t0 = core::Clock::now();
  auto clock = std::make_shared<core::ManualClock>(t0);
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
  command(*clock, *controller, 0.0, 0.5);
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
}  // namespace serial_robot_driver::devices::base
