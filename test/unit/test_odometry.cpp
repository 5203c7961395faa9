// Odometry against poses worked out by hand on circles and lines (wheel separation 0.40 m).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "serial_robot_driver/kinematics/odometry.h"

namespace serial_robot_driver::kinematics {
namespace {

constexpr double kSeparation = 0.40;
constexpr double kPoseTol = 1e-9;
constexpr double kPi = 3.14159265358979323846;

void expectPose(const Pose2D& pose, double x, double y, double yaw) {
  EXPECT_NEAR(pose.x, x, kPoseTol);
  EXPECT_NEAR(pose.y, y, kPoseTol);
  EXPECT_NEAR(pose.yaw, yaw, kPoseTol);
}

TEST(Odometry, StraightLine) {
  Odometry odometry(kSeparation);
  odometry.integrate(WheelSpeeds(0.5, 0.5), 2.0);  // 0.5 m/s for 2 s
  expectPose(odometry.pose(), 1.0, 0.0, 0.0);
  EXPECT_NEAR(odometry.linear(), 0.5, kPoseTol);
  EXPECT_NEAR(odometry.angular(), 0.0, kPoseTol);
  EXPECT_NEAR(odometry.travelled(), 1.0, kPoseTol);
}

TEST(Odometry, QuarterCircleInOneStepAndInManySteps) {
  // left 0.1, right 0.3: v = 0.2 m/s, w = 0.2 / 0.4 = 0.5 rad/s, radius 0.4 m. After pi s the
  // heading is pi/2 and the robot is at (r, r) = (0.4, 0.4).
  Odometry one_step(kSeparation);
  one_step.integrate(WheelSpeeds(0.1, 0.3), kPi);
  expectPose(one_step.pose(), 0.4, 0.4, kPi / 2);
  EXPECT_NEAR(one_step.angular(), 0.5, kPoseTol);

  Odometry many_steps(kSeparation);
  for (int i = 0; i < 157; ++i) many_steps.integrate(WheelSpeeds(0.1, 0.3), kPi / 157);
  expectPose(many_steps.pose(), 0.4, 0.4, kPi / 2);
}

TEST(Odometry, ClockwiseArcGoesRight) {
  // Mirror of the quarter circle: left 0.3, right 0.1 ends at (0.4, -0.4) facing -pi/2.
  Odometry odometry(kSeparation);
  odometry.integrate(WheelSpeeds(0.3, 0.1), kPi);
  expectPose(odometry.pose(), 0.4, -0.4, -kPi / 2);
}

TEST(Odometry, FullCircleComesBackToTheStart) {
  Odometry odometry(kSeparation);
  // w = 0.5 rad/s: one turn takes 4 pi s; halfway the robot is at (0, 2r) = (0, 0.8) facing back.
  for (int i = 0; i < 5; ++i) odometry.integrate(WheelSpeeds(0.1, 0.3), 4 * kPi / 10);
  EXPECT_NEAR(odometry.pose().x, 0.0, kPoseTol);
  EXPECT_NEAR(odometry.pose().y, 0.8, kPoseTol);
  EXPECT_NEAR(std::abs(odometry.pose().yaw), kPi, kPoseTol);
  for (int i = 0; i < 5; ++i) odometry.integrate(WheelSpeeds(0.1, 0.3), 4 * kPi / 10);
  expectPose(odometry.pose(), 0.0, 0.0, 0.0);
  // Both wheels' mean path: 0.2 m/s for 4 pi s.
  EXPECT_NEAR(odometry.travelled(), 0.2 * 4 * kPi, kPoseTol);
}

TEST(Odometry, TurnOnTheSpotThenDriveAlongTheNewHeading) {
  // -0.2 / +0.2: w = 0.4 / 0.4 = 1 rad/s, no translation.
  Odometry odometry(kSeparation);
  odometry.integrate(WheelSpeeds(-0.2, 0.2), kPi / 2);
  expectPose(odometry.pose(), 0.0, 0.0, kPi / 2);
  odometry.integrate(WheelSpeeds(0.25, 0.25), 4.0);  // 1 m along +y
  expectPose(odometry.pose(), 0.0, 1.0, kPi / 2);
  // Turning on the spot moves the wheels: 0.2 m/s * pi/2 s, then 1 m.
  EXPECT_NEAR(odometry.travelled(), 0.1 * kPi + 1.0, kPoseTol);
}

TEST(Odometry, TinyTurnUsesTheMidpointStepAndMatchesTheArc) {
  // v = 0.5 m/s, w = 1e-9 / 0.4 = 2.5e-9 rad/s: the arc radius would be 2e8 m. Over 1 s the arc
  // ends at x = r sin(th) ~ 0.5, y = r (1 - cos th) ~ v dt th / 2 = 0.5 * 2.5e-9 / 2 = 6.25e-10.
  Odometry odometry(kSeparation);
  odometry.integrate(WheelSpeeds(0.5 - 5e-10, 0.5 + 5e-10), 1.0);
  EXPECT_NEAR(odometry.pose().x, 0.5, 1e-12);
  EXPECT_NEAR(odometry.pose().y, 6.25e-10, 1e-15);
  EXPECT_NEAR(odometry.pose().yaw, 2.5e-9, 1e-15);
}

TEST(Odometry, YawWrapsIntoMinusPiToPi) {
  Odometry odometry(kSeparation);
  odometry.integrate(WheelSpeeds(-0.2, 0.2), 1.5 * kPi);  // three quarter turns left
  EXPECT_NEAR(odometry.pose().yaw, -kPi / 2, kPoseTol);
}

TEST(Odometry, CovarianceGrowsWithDistanceAndResetClearsIt) {
  PoseCovarianceModel model;
  Odometry odometry(kSeparation, model);
  EXPECT_NEAR(odometry.positionVariance(), model.initial_position_variance, kPoseTol);
  EXPECT_NEAR(odometry.yawVariance(), model.initial_yaw_variance, kPoseTol);
  EXPECT_GT(odometry.positionVariance(), 0.0);

  odometry.integrate(WheelSpeeds(0.5, 0.5), 4.0);  // 2 m
  EXPECT_NEAR(odometry.positionVariance(), 1e-6 + 0.0025 * 2.0, kPoseTol);
  EXPECT_NEAR(odometry.yawVariance(), 1e-6 + 0.01 * 2.0, kPoseTol);
  // Standing still adds nothing: the uncertainty is about the wheels' motion, not time.
  odometry.integrate(WheelSpeeds(0.0, 0.0), 10.0);
  EXPECT_NEAR(odometry.positionVariance(), 1e-6 + 0.0025 * 2.0, kPoseTol);

  odometry.reset();
  expectPose(odometry.pose(), 0.0, 0.0, 0.0);
  EXPECT_NEAR(odometry.travelled(), 0.0, kPoseTol);
  EXPECT_NEAR(odometry.positionVariance(), model.initial_position_variance, kPoseTol);
}

TEST(Odometry, NonFiniteInputLeavesThePoseAlone) {
  Odometry odometry(kSeparation);
  odometry.integrate(WheelSpeeds(0.5, 0.5), 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  odometry.integrate(WheelSpeeds(nan, 0.5), 1.0);
  odometry.integrate(WheelSpeeds(inf, inf), 1.0);
  odometry.integrate(WheelSpeeds(0.5, 0.5), nan);
  odometry.integrate(WheelSpeeds(0.5, 0.5), -1.0);
  expectPose(odometry.pose(), 0.5, 0.0, 0.0);
}

}  // namespace
}  // namespace serial_robot_driver::kinematics
