// The trajectory core against hand-computed values: each interpolation, segment boundaries,
// points in the past, replacement, goal validation and tolerances.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "serial_robot_driver/trajectory/bus_joint.h"
#include "serial_robot_driver/trajectory/command.h"
#include "serial_robot_driver/trajectory/command_start.h"
#include "serial_robot_driver/trajectory/spline.h"
#include "serial_robot_driver/trajectory/tolerances.h"

namespace serial_robot_driver::trajectory {
namespace {

constexpr double kEps = 1e-12;

Waypoint point(double time, double position, Interpolation order = Interpolation::kLinear,
               double velocity = 0.0, double acceleration = 0.0) {
  return {time, {position, velocity, acceleration}, order};
}

TEST(Segment, LinearWithPositionsOnly) {
  // 0 -> 1 rad over 2 s: 0.5 rad/s throughout.
  const Segment segment(0.0, {0.0, 0.0, 0.0}, 2.0, {1.0, 0.0, 0.0}, Interpolation::kLinear);
  const JointSample s = segment.sample(0.5);
  EXPECT_NEAR(s.position, 0.25, kEps);
  EXPECT_NEAR(s.velocity, 0.5, kEps);
  EXPECT_NEAR(s.acceleration, 0.0, kEps);
}

TEST(Segment, CubicWithVelocities) {
  // 0 -> 1 rad in 1 s, at rest at both ends: p = 3t^2 - 2t^3.
  const Segment segment(0.0, {0.0, 0.0, 0.0}, 1.0, {1.0, 0.0, 0.0}, Interpolation::kCubic);
  JointSample s = segment.sample(0.25);
  EXPECT_NEAR(s.position, 0.15625, kEps);
  EXPECT_NEAR(s.velocity, 1.125, kEps);
  EXPECT_NEAR(s.acceleration, 3.0, kEps);
  s = segment.sample(0.5);
  EXPECT_NEAR(s.position, 0.5, kEps);
  EXPECT_NEAR(s.velocity, 1.5, kEps);
  // Ending at 1 rad/s: p = 2t^2 - t^3.
  const Segment moving(0.0, {0.0, 0.0, 0.0}, 1.0, {1.0, 1.0, 0.0}, Interpolation::kCubic);
  EXPECT_NEAR(moving.sample(0.5).position, 0.375, kEps);
  EXPECT_NEAR(moving.sample(1.0).velocity, 1.0, kEps);
}

TEST(Segment, QuinticWithAccelerations) {
  // 0 -> 1 rad in 1 s, at rest: p = 10t^3 - 15t^4 + 6t^5.
  const Segment segment(0.0, {0.0, 0.0, 0.0}, 1.0, {1.0, 0.0, 0.0}, Interpolation::kQuintic);
  const JointSample s = segment.sample(0.25);
  EXPECT_NEAR(s.position, 0.103515625, kEps);
  EXPECT_NEAR(s.velocity, 1.0546875, kEps);
  EXPECT_NEAR(s.acceleration, 5.625, kEps);
  EXPECT_NEAR(segment.sample(0.5).velocity, 1.875, kEps);
}

TEST(Segment, StartsLaterAndHoldsOutsideItsSpan) {
  const Segment segment(10.0, {1.0, 0.0, 0.0}, 12.0, {2.0, 0.0, 0.0}, Interpolation::kLinear);
  EXPECT_NEAR(segment.sample(11.0).position, 1.5, kEps);
  const JointSample before = segment.sample(9.0);
  EXPECT_NEAR(before.position, 1.0, kEps);
  EXPECT_EQ(before.velocity, 0.0);
  const JointSample after = segment.sample(13.0);
  EXPECT_NEAR(after.position, 2.0, kEps);
  EXPECT_EQ(after.velocity, 0.0);
}

TEST(JointSpline, HoldsUntilSomethingIsSpliced) {
  const JointSpline spline(0.7);
  EXPECT_TRUE(spline.holding());
  EXPECT_EQ(spline.sample(123.0).position, 0.7);
}

TEST(JointSpline, SegmentBoundaries) {
  // From 0 rad held, spliced at t = 0: 1 rad at t = 1, 3 rad at t = 2 (linear).
  JointSpline spline(0.0);
  spline.splice(0.0, {point(1.0, 1.0), point(2.0, 3.0)});
  EXPECT_NEAR(spline.sample(0.5).position, 0.5, kEps);
  EXPECT_NEAR(spline.sample(1.0).position, 1.0, kEps);
  EXPECT_NEAR(spline.sample(1.5).position, 2.0, kEps);
  EXPECT_NEAR(spline.sample(1.5).velocity, 2.0, kEps);
  EXPECT_NEAR(spline.sample(2.0).position, 3.0, kEps);
  EXPECT_NEAR(spline.sample(5.0).position, 3.0, kEps);
  EXPECT_EQ(spline.sample(5.0).velocity, 0.0);
  EXPECT_EQ(spline.endTime(), 2.0);
}

TEST(JointSpline, StampedAheadHoldsWhereItStarts) {
  // Spliced at t = 10 (a stamp in the future): before that the joint stays at 0.5 rad.
  JointSpline spline(0.5);
  spline.splice(10.0, {point(11.0, 1.5)});
  EXPECT_NEAR(spline.sample(3.0).position, 0.5, kEps);
  EXPECT_NEAR(spline.sample(10.5).position, 1.0, kEps);
}

TEST(JointSpline, ReplacementStartsFromTheDesiredStateWithoutAJump) {
  // Running 0 -> 2 rad over 2 s (p = t); at t = 1 a new command sends it back to 0 by t = 2.
  JointSpline spline(0.0);
  spline.splice(0.0, {point(2.0, 2.0)});
  spline.splice(1.0, {point(2.0, 0.0)});
  EXPECT_NEAR(spline.sample(0.5).position, 0.5, kEps);  // what ran is kept
  EXPECT_NEAR(spline.sample(1.0).position, 1.0, kEps);  // no jump
  EXPECT_NEAR(spline.sample(1.5).position, 0.5, kEps);
  EXPECT_NEAR(spline.sample(2.0).position, 0.0, kEps);

  // With velocities the bridge is a cubic from (1 rad, 1 rad/s) to (0 rad, 0 rad/s) in 1 s:
  // p = 1 + t - 5t^2 + 3t^3, so the velocity does not jump either.
  JointSpline smooth(0.0);
  smooth.splice(0.0, {point(2.0, 2.0)});
  smooth.splice(1.0, {point(2.0, 0.0, Interpolation::kCubic, 0.0)});
  EXPECT_NEAR(smooth.sample(1.0).velocity, 1.0, kEps);
  EXPECT_NEAR(smooth.sample(1.5).position, 0.625, kEps);
}

TEST(JointSpline, EmptySpliceHoldsTheStateThere) {
  JointSpline spline(0.0);
  spline.splice(0.0, {point(2.0, 2.0)});
  spline.splice(0.5, {});
  EXPECT_TRUE(spline.holding());
  EXPECT_NEAR(spline.sample(3.0).position, 0.5, kEps);
}

TEST(JointSpline, PruneKeepsWhatIsAhead) {
  JointSpline spline(0.0);
  spline.splice(0.0, {point(1.0, 1.0), point(2.0, 3.0)});
  spline.prune(1.5);
  EXPECT_NEAR(spline.sample(1.5).position, 2.0, kEps);
  spline.prune(10.0);
  EXPECT_TRUE(spline.holding());
  EXPECT_NEAR(spline.sample(10.0).position, 3.0, kEps);
}

// --- commands ---------------------------------------------------------------------------------

const std::vector<JointRange> kJoints = {{"a", -1.0, 1.0}, {"b", -2.0, 2.0}};

TrajectoryCommand twoPointCommand() {
  TrajectoryCommand command;
  command.joint_names = {"b", "a"};
  command.points = {{0.5, {0.1, 0.2}, {}, {}}, {1.0, {0.3, 0.4}, {}, {}}};
  return command;
}

TEST(Validate, AcceptsAGoodCommandAndMapsItsJoints) {
  const CommandCheck check = validate(twoPointCommand(), kJoints, 0.0);
  ASSERT_TRUE(check.ok()) << check.message;
  EXPECT_EQ(check.joint_indices, (std::vector<std::size_t>{1, 0}));
}

TEST(Validate, UnknownAndDuplicateJoints) {
  TrajectoryCommand command = twoPointCommand();
  command.joint_names = {"b", "elbow"};
  CommandCheck check = validate(command, kJoints, 0.0);
  EXPECT_EQ(check.error, CommandError::kInvalidJoints);
  EXPECT_NE(check.message.find("'elbow'"), std::string::npos) << check.message;
  command.joint_names = {"a", "a"};
  check = validate(command, kJoints, 0.0);
  EXPECT_EQ(check.error, CommandError::kInvalidJoints);
  EXPECT_NE(check.message.find("'a'"), std::string::npos) << check.message;
}

TEST(Validate, NotFiniteNamesJointAndPoint) {
  TrajectoryCommand command = twoPointCommand();
  command.points[1].positions[1] = std::numeric_limits<double>::quiet_NaN();
  const CommandCheck check = validate(command, kJoints, 0.0);
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_NE(check.message.find("joint 'a', point 1"), std::string::npos) << check.message;
}

TEST(Validate, TimesMustIncrease) {
  TrajectoryCommand command = twoPointCommand();
  command.points[1].time_from_start = 0.5;
  const CommandCheck check = validate(command, kJoints, 0.0);
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_NE(check.message.find("point 1"), std::string::npos) << check.message;
}

TEST(Validate, LengthsMustMatch) {
  TrajectoryCommand command = twoPointCommand();
  command.points[0].velocities = {0.0};
  const CommandCheck check = validate(command, kJoints, 0.0);
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_EQ(check.message, "point 0 has 1 velocities for 2 joints");
}

TEST(Validate, UnreachableTarget) {
  TrajectoryCommand command = twoPointCommand();
  command.points[1].positions[1] = 1.5;  // 'a' reaches -1 .. 1
  const CommandCheck check = validate(command, kJoints, 0.0);
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_NE(check.message.find("joint 'a', point 1: 1.5000 rad is outside"), std::string::npos)
      << check.message;
}

TEST(Validate, SpeedsAboveMaxVelocity) {
  // 'b' goes 0.1 -> 0.3 rad in 0.5 s: 0.4 rad/s.
  EXPECT_TRUE(validate(twoPointCommand(), kJoints, 0.4).ok());
  CommandCheck check = validate(twoPointCommand(), kJoints, 0.39);
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_NE(check.message.find("joint 'b', point 1"), std::string::npos) << check.message;

  TrajectoryCommand command = twoPointCommand();
  command.points[0].velocities = {0.0, -0.5};
  check = validate(command, kJoints, 0.45);
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_NE(check.message.find("joint 'a', point 0: velocity -0.5000"), std::string::npos)
      << check.message;

  // The bridge: 'a' from 0.9 rad to 0.2 rad in 0.5 s is 1.4 rad/s.
  check = validate(twoPointCommand(), kJoints, 1.0, 0.0, {0.1, 0.9});
  EXPECT_EQ(check.error, CommandError::kInvalidGoal);
  EXPECT_NE(check.message.find("joint 'a', point 0"), std::string::npos) << check.message;
  EXPECT_TRUE(validate(twoPointCommand(), kJoints, 1.5, 0.0, {0.1, 0.9}).ok());
}

TEST(Validate, EveryPointInThePast) {
  const CommandCheck check = validate(twoPointCommand(), kJoints, 0.0, -3.0);
  EXPECT_EQ(check.error, CommandError::kOldTimestamp);
  EXPECT_NE(check.message.find("2.000 s ago"), std::string::npos) << check.message;
  // The last point still ahead: valid.
  EXPECT_TRUE(validate(twoPointCommand(), kJoints, 0.0, -0.8).ok());
}

TEST(Validate, NoPointsMeansStop) {
  TrajectoryCommand command;
  command.joint_names = {"a"};
  EXPECT_TRUE(validate(command, kJoints, 0.0).ok());
}

TEST(EffectiveStart, KeepsAStartNowOrAhead) {
  EXPECT_EQ(effectiveStart(twoPointCommand(), 10.0, 10.0), 10.0);
  EXPECT_EQ(effectiveStart(twoPointCommand(), 12.5, 10.0), 12.5);
}

TEST(EffectiveStart, ALateStartNeverShortensTheBridgeBelowWhatTheCommandPlanned) {
  // Points at 0.5 s and 1.0 s. Stamped 0.45 s ago: 0.05 s would be left to reach the first point
  // (joint_trajectory_controller's bridge); it gets its own 0.5 s, as if stamped now.
  EXPECT_NEAR(effectiveStart(twoPointCommand(), 9.55, 10.0), 10.0, 1e-12);
  // Stamped 0.7 s ago: the first point is past and dropped; the second, 0.3 s away, was planned
  // 0.5 s after the first: the command starts 0.2 s later, leaving the bridge 0.5 s.
  EXPECT_NEAR(effectiveStart(twoPointCommand(), 9.3, 10.0), 9.5, 1e-12);
  // In effect the segment running now runs whole from now: its start point is put at now.
  TrajectoryCommand command = twoPointCommand();
  command.points[0].time_from_start = 0.25;
  EXPECT_NEAR(effectiveStart(command, 9.7, 10.0), 10.0 - 0.25, 1e-12);
  // Every point past: as stamped (validate() says kOldTimestamp).
  EXPECT_EQ(effectiveStart(twoPointCommand(), 5.0, 10.0), 5.0);
}

TEST(WaypointsFor, DropsPointsInThePast) {
  TrajectoryCommand command = twoPointCommand();
  command.points.insert(command.points.begin(), TrajectoryPoint{0.25, {0.0, 0.0}, {}, {}});
  command.points[2].velocities = {0.7, 0.8};
  // Started at t = 10, now 10.6: the points at 10.25 and 10.5 are gone.
  const std::vector<Waypoint> waypoints = waypointsFor(command, 1, 10.0, 10.6);
  ASSERT_EQ(waypoints.size(), 1u);
  EXPECT_EQ(waypoints[0].time, 11.0);
  EXPECT_EQ(waypoints[0].sample.position, 0.4);
  EXPECT_EQ(waypoints[0].sample.velocity, 0.8);
  EXPECT_EQ(waypoints[0].order, Interpolation::kCubic);
}

// --- tolerances -------------------------------------------------------------------------------

TEST(Tolerances, GoalValuesOverrideDefaults) {
  EXPECT_EQ(overrideTolerance(0.05, 0.0), 0.05);   // 0: default
  EXPECT_EQ(overrideTolerance(0.05, -1.0), 0.0);   // -1: not checked
  EXPECT_EQ(overrideTolerance(0.05, 0.2), 0.2);
  const auto resolved =
      resolveTolerances({"a", "b"}, {0.05, 0.0}, {{"b", 0.3, 0.0}, {"elsewhere", 9.0, 9.0}});
  EXPECT_EQ(resolved[0].position, 0.05);
  EXPECT_EQ(resolved[1].position, 0.3);
}

TEST(Tolerances, FirstViolationNamesJointAndAmount) {
  const std::vector<std::string> joints = {"a", "b"};
  const std::vector<JointTolerance> tolerances = {{0.1, 0.0}, {0.1, 0.0}};
  const std::vector<JointSample> desired = {{0.0, 0, 0}, {1.0, 0, 0}};
  EXPECT_FALSE(findViolation(joints, tolerances, desired, {{0.05, 0, 0}, {0.95, 5, 0}}, "path"));
  const auto violation =
      findViolation(joints, tolerances, desired, {{0.05, 0, 0}, {1.25, 0, 0}}, "path");
  ASSERT_TRUE(violation);
  EXPECT_EQ(violation->joint, 1u);
  EXPECT_EQ(violation->message,
            "joint 'b': position error 0.2500 rad is beyond the path tolerance 0.1000 rad");
}

// --- bus servo joints -----------------------------------------------------------------------

TEST(BusJoint, MapsJointRadiansToServoDegrees) {
  const BusJoint joint{7, "pan", 30.0, -1};
  EXPECT_NEAR(joint.toServoDegrees(M_PI / 2), 30.0 - 90.0, kEps);
  EXPECT_NEAR(joint.toRadians(-60.0), M_PI / 2, kEps);
  // -180 .. 180 deg of the servo: joint -150 deg .. 210 deg, flipped by the direction.
  const JointRange range = joint.range();
  EXPECT_NEAR(range.min_position, -150.0 * M_PI / 180.0, kEps);
  EXPECT_NEAR(range.max_position, 210.0 * M_PI / 180.0, kEps);
}

TEST(BusJoint, EachSegmentIsOneMoveAtItsStart) {
  JointSpline spline(0.0);
  spline.splice(10.0, {point(11.0, 0.5), point(13.0, 1.5)});
  EXPECT_FALSE(segmentMoveAt(spline, 9.0, NAN)) << "not started";
  auto move = segmentMoveAt(spline, 10.02, NAN);
  ASSERT_TRUE(move);
  EXPECT_NEAR(move->position, 0.5, kEps);
  EXPECT_NEAR(move->duration, 0.98, kEps);  // the time left to the segment's end
  EXPECT_FALSE(segmentMoveAt(spline, 10.5, 10.0)) << "its move went out already";
  move = segmentMoveAt(spline, 11.0, 10.0);
  ASSERT_TRUE(move);
  EXPECT_NEAR(move->position, 1.5, kEps);
  EXPECT_NEAR(move->duration, 2.0, kEps);
  EXPECT_FALSE(segmentMoveAt(spline, 13.0, 11.0)) << "over";
}

}  // namespace
}  // namespace serial_robot_driver::trajectory
