// HeadingFusion (the IMU's yaw as odometry's heading) and Odometry's integration along a measured
// heading: anchoring, yaw wrap across +-pi, odometry resets, and fallback and resume without jumps.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "serial_robot_driver/kinematics/heading_fusion.h"
#include "serial_robot_driver/kinematics/odometry.h"

namespace serial_robot_driver::kinematics {
namespace {

using std::chrono::milliseconds;
constexpr double kTol = 1e-12;
constexpr double kPi = 3.14159265358979323846;

class HeadingFusionTest : public ::testing::Test {
 protected:
  /// The fusion's heading at t0 + `ms`, given odometry's heading before the step.
  std::optional<double> at(int ms, double odom_yaw) {
    return fusion_.heading(t0_ + milliseconds(ms), odom_yaw);
  }
  void sample(int ms, double imu_yaw) { fusion_.addSample(imu_yaw, t0_ + milliseconds(ms)); }

  const SteadyClock::time_point t0_ = SteadyClock::now();
  HeadingFusion fusion_{milliseconds(250)};
};

TEST_F(HeadingFusionTest, WithoutAnySampleTheHeadingIsCommanded) {
  EXPECT_FALSE(at(0, 0.3).has_value());
  EXPECT_EQ(fusion_.source(), HeadingSource::kWaitingForImu);
  EXPECT_FALSE(fusion_.sampleAge(t0_).has_value());
  EXPECT_EQ(fusion_.fallbacks(), 0u);
}

TEST_F(HeadingFusionTest, TheFirstSampleAnchorsAtOdometrysHeadingThenTheImuTurnsIt) {
  sample(0, 2.0);
  ASSERT_TRUE(at(20, 0.5).has_value());
  EXPECT_NEAR(*at(20, 0.5), 0.5, kTol);  // no jump: the IMU's 2.0 rad count as odometry's 0.5
  EXPECT_EQ(fusion_.source(), HeadingSource::kImu);
  sample(20, 2.3);
  // Once anchored, odometry's own heading no longer matters: the IMU's turn does.
  EXPECT_NEAR(*at(40, 123.0), 0.8, kTol);
  sample(40, 1.9);
  EXPECT_NEAR(*at(60, 0.8), 0.4, kTol);
  EXPECT_NEAR(*fusion_.sampleAge(t0_ + milliseconds(60)), 0.020, 1e-9);
}

TEST_F(HeadingFusionTest, ImuYawWrappingAcrossPiIsASmallTurn) {
  // The IMU goes from 3.1 rad to -3.1 rad: a 0.083 rad counter-clockwise turn, not -6.2 rad.
  sample(0, 3.1);
  EXPECT_NEAR(*at(20, 0.0), 0.0, kTol);
  sample(20, -3.1);
  EXPECT_NEAR(*at(40, 0.0), 2 * kPi - 6.2, kTol);
  // Odometry's own heading wraps as well: anchored at 3.1, the same turn ends near -3.1.
  HeadingFusion near_pi(milliseconds(250));
  near_pi.addSample(0.0, t0_);
  EXPECT_NEAR(*near_pi.heading(t0_, 3.1), 3.1, kTol);
  near_pi.addSample(2 * kPi - 6.2, t0_ + milliseconds(20));
  EXPECT_NEAR(*near_pi.heading(t0_ + milliseconds(20), 3.1), -3.1, kTol);
}

TEST_F(HeadingFusionTest, RestartMakesTheImusYawNowTheResetHeading) {
  sample(0, 1.0);
  at(0, 0.0);
  sample(20, 1.5);
  EXPECT_NEAR(*at(20, 0.0), 0.5, kTol);
  fusion_.restart();  // odometry was reset to heading 0
  EXPECT_NEAR(*at(30, 0.0), 0.0, kTol);
  sample(40, 1.6);
  EXPECT_NEAR(*at(40, 0.0), 0.1, kTol);
  EXPECT_EQ(fusion_.fallbacks(), 0u);
}

TEST_F(HeadingFusionTest, StaleImuFallsBackAndItsReturnContinuesFromOdometrysHeading) {
  sample(0, 0.0);
  EXPECT_NEAR(*at(0, 0.0), 0.0, kTol);
  sample(100, 0.4);
  EXPECT_NEAR(*at(100, 0.0), 0.4, kTol);
  // Fresh up to 250 ms after the newest sample, stale after.
  EXPECT_NEAR(*at(350, 0.4), 0.4, kTol);
  EXPECT_FALSE(at(351, 0.4).has_value());
  EXPECT_EQ(fusion_.source(), HeadingSource::kImuStale);
  EXPECT_EQ(fusion_.fallbacks(), 1u);
  EXPECT_FALSE(at(500, 0.6).has_value());
  EXPECT_EQ(fusion_.fallbacks(), 1u) << "one fallback per outage";
  // Meanwhile odometry integrated the commanded turn to 0.9 rad. The IMU returns at -2.0 rad:
  // odometry's heading stays 0.9, and the IMU's turns count from there.
  sample(900, -2.0);
  EXPECT_NEAR(*at(900, 0.9), 0.9, kTol);
  EXPECT_EQ(fusion_.source(), HeadingSource::kImu);
  sample(920, -1.9);
  EXPECT_NEAR(*at(920, 0.9), 1.0, kTol);
}

TEST_F(HeadingFusionTest, OlderAndNonFiniteSamplesAreIgnored) {
  sample(100, 1.0);
  EXPECT_NEAR(*at(100, 0.0), 0.0, kTol);
  sample(50, 3.0);  // older than what the fusion has
  fusion_.addSample(std::numeric_limits<double>::quiet_NaN(), t0_ + milliseconds(110));
  EXPECT_NEAR(*at(120, 0.0), 0.0, kTol);
}

// --- Odometry along a measured heading -------------------------------------------------------

TEST(OdometryMeasuredHeading, PositionFollowsTheMeasuredTurnNotTheWheels) {
  // Wheels straight at 0.2 m/s for pi s (0.628 m), but the heading measured at pi/2 after it:
  // the arc through a quarter turn of that length has radius 0.4 m and ends at (0.4, 0.4).
  Odometry odometry(0.40);
  odometry.integrate(WheelSpeeds(0.2, 0.2), kPi, kPi / 2, 0.0003);
  EXPECT_NEAR(odometry.pose().x, 0.4, 1e-9);
  EXPECT_NEAR(odometry.pose().y, 0.4, 1e-9);
  EXPECT_NEAR(odometry.pose().yaw, kPi / 2, 1e-12);
  // Then straight on along the measured heading: +y.
  odometry.integrate(WheelSpeeds(0.5, 0.5), 2.0, kPi / 2, 0.0003);
  EXPECT_NEAR(odometry.pose().x, 0.4, 1e-9);
  EXPECT_NEAR(odometry.pose().y, 1.4, 1e-9);
}

TEST(OdometryMeasuredHeading, MeasuredTurnAcrossPiTakesTheShortWay) {
  Odometry odometry(0.40);
  odometry.integrate(WheelSpeeds(0, 0), 0.0, 3.1, 0.0003);  // dt 0: only the heading
  EXPECT_NEAR(odometry.pose().yaw, 3.1, 1e-12);
  EXPECT_NEAR(odometry.pose().x, 0.0, 1e-12);
  // 0.1 m while the heading goes from 3.1 through pi to -3.1: the robot moves along -x.
  odometry.integrate(WheelSpeeds(0.1, 0.1), 1.0, -3.1, 0.0003);
  EXPECT_NEAR(odometry.pose().yaw, -3.1, 1e-12);
  EXPECT_NEAR(odometry.pose().x, -0.1, 1e-4);
  EXPECT_NEAR(odometry.pose().y, 0.0, 1e-4);
}

TEST(OdometryMeasuredHeading, YawVarianceRestartsAtTheMeasurementAndGrowsWithoutIt) {
  PoseCovarianceModel model;
  Odometry odometry(0.40, model);
  odometry.integrate(WheelSpeeds(0.5, 0.5), 2.0);  // 1 m commanded
  EXPECT_NEAR(odometry.yawVariance(), model.initial_yaw_variance + model.yaw_variance_per_meter,
              kTol);
  odometry.integrate(WheelSpeeds(0.5, 0.5), 2.0, 0.0, 0.0003);  // 1 m along the IMU's heading
  EXPECT_NEAR(odometry.yawVariance(), 0.0003, kTol);
  odometry.integrate(WheelSpeeds(0.5, 0.5), 4.0);  // the IMU is gone: 2 m commanded
  EXPECT_NEAR(odometry.yawVariance(), 0.0003 + 2 * model.yaw_variance_per_meter, kTol);
  // The position variance ignores the heading's source: 4 m travelled in all.
  EXPECT_NEAR(odometry.positionVariance(),
              model.initial_position_variance + 4 * model.position_variance_per_meter, kTol);
  odometry.reset();
  EXPECT_NEAR(odometry.yawVariance(), model.initial_yaw_variance, kTol);
}

TEST(OdometryMeasuredHeading, NonFiniteMeasurementLeavesThePoseUnchanged) {
  Odometry odometry(0.40);
  odometry.integrate(WheelSpeeds(0.5, 0.5), 1.0, std::numeric_limits<double>::quiet_NaN(), 0.0003);
  EXPECT_EQ(odometry.pose().x, 0.0);
  EXPECT_EQ(odometry.pose().yaw, 0.0);
}

}  // namespace
}  // namespace serial_robot_driver::kinematics
