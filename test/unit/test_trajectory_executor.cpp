// The trajectory executor without ROS: goals accepted or rejected (with the action's codes and
// texts), the splines sampled each tick, path and goal tolerances, the goal time tolerance,
// preemption, what a cancel or lost telemetry holds, and take-overs. Time is a number the tests
// step by hand. Start times and e-stops: test_trajectory_executor_start.cpp.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/trajectory/executor.h"
#include "support/trajectory_executor_rig.h"

namespace serial_robot_driver::trajectory {
namespace {

using test::ExecutorRig;
using test::GoalLog;
using test::kEps;

TEST_F(ExecutorRig, RejectsEveryGoalBeforeStartAndAfterShutdown) {
  TrajectoryExecutor idle(groups(), defaults(), [this] { return now; });
  GoalLog log;
  idle.submitGoal(goalTo({"arm_1"}, {0.5}), log.callbacks());
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.accepted, 0);
  EXPECT_EQ(log.outcome().status, GoalStatus::kRejected);
  EXPECT_EQ(log.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(log.outcome().error_string, "the driver is not running");
  EXPECT_EQ(log.outcome().text, "the driver is not running");

  measure({"arm_1"}, {0.0});
  GoalLog running;
  executor.submitGoal(goalTo({"arm_1"}, {0.5}), running.callbacks());
  executor.shutdown();
  ASSERT_TRUE(running.over());
  EXPECT_EQ(running.outcome().status, GoalStatus::kAborted);
  EXPECT_EQ(running.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(running.outcome().text, "the driver is shutting down");
  executor.shutdown();  // idempotent: told once
  EXPECT_EQ(running.outcomes.size(), 1u);
}

TEST_F(ExecutorRig, AcceptanceErrorsCarryTheActionsCodes) {
  GoalLog unknown;
  executor.submitGoal(goalTo({"elbow"}, {0.5}), unknown.callbacks());
  EXPECT_EQ(unknown.outcome().status, GoalStatus::kRejected);
  EXPECT_EQ(unknown.outcome().error_code, result_code::kInvalidJoints);

  // Never measured: nobody knows where the bridge would start.
  GoalLog unmeasured;
  executor.submitGoal(goalTo({"arm_1"}, {0.5}), unmeasured.callbacks());
  EXPECT_EQ(unmeasured.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(unmeasured.outcome().error_string,
            "joint 'arm_1': no recent measurement (is its telemetry or poll arriving?), so the "
            "trajectory cannot start from where it is");

  measure({"arm_1"}, {0.0});
  Goal old = goalTo({"arm_1"}, {0.5});
  old.start_time = now - 10.0;
  GoalLog late;
  executor.submitGoal(old, late.callbacks());
  EXPECT_EQ(late.outcome().error_code, result_code::kOldHeaderTimestamp);

  GoalLog unreachable;
  executor.submitGoal(goalTo({"arm_1"}, {5.0}), unreachable.callbacks());
  EXPECT_EQ(unreachable.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(unreachable.accepted + unknown.accepted + unmeasured.accepted + late.accepted, 0);
  EXPECT_EQ(warnings.size(), 4u);
  EXPECT_EQ(warnings[0].rfind("follow_joint_trajectory: goal rejected: ", 0), 0u);

  // The speed limit comes from the defaults in force when the goal arrives.
  GoalDefaults slow = defaults();
  slow.max_velocity = 0.1;
  executor.retune(slow);
  GoalLog fast;
  executor.submitGoal(goalTo({"arm_1"}, {0.5}), fast.callbacks());
  EXPECT_EQ(fast.outcome().error_code, result_code::kInvalidGoal);
  GoalLog gentle;
  executor.submitGoal(goalTo({"arm_1"}, {0.05}), gentle.callbacks());
  EXPECT_EQ(gentle.accepted, 1);
  EXPECT_FALSE(gentle.over());
}

TEST_F(ExecutorRig, SamplesTheSplineEachTickAndSucceedsWithinTheGoalTolerance) {
  measure({"arm_1"}, {0.0}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  EXPECT_EQ(log.accepted, 1);
  EXPECT_FALSE(log.over());

  measure({"arm_1"}, {0.4}, {1.0});
  tickAt(100.5);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].first, std::vector<std::string>{"arm_1"});
  EXPECT_NEAR(frames[0].second.at(0), 0.5, kEps);  // linear: halfway at half time
  ASSERT_EQ(log.feedback.size(), 1u);
  const GoalFeedback& feedback = log.feedback[0];
  EXPECT_EQ(feedback.joint_names, std::vector<std::string>{"arm_1"});
  EXPECT_NEAR(feedback.time_from_start, 0.5, kEps);
  EXPECT_NEAR(feedback.desired.at(0).position, 0.5, kEps);
  EXPECT_NEAR(feedback.desired.at(0).velocity, 1.0, kEps);
  EXPECT_NEAR(feedback.actual_positions.at(0), 0.4, kEps);
  EXPECT_NEAR(feedback.error_positions.at(0), 0.1, kEps);
  EXPECT_NEAR(feedback.actual_velocities.at(0), 1.0, kEps);
  EXPECT_NEAR(feedback.error_velocities.at(0), 0.0, kEps);

  measure({"arm_1"}, {0.98});  // no velocity: unknown, never a violation, not in the feedback
  tickAt(101.0);
  ASSERT_TRUE(log.over());
  EXPECT_TRUE(log.feedback.back().actual_velocities.empty());
  EXPECT_EQ(log.outcome().status, GoalStatus::kSucceeded);
  EXPECT_EQ(log.outcome().error_code, result_code::kSuccessful);
  EXPECT_EQ(log.outcome().error_string, "");
  EXPECT_EQ(log.outcome().text, "reached");
  EXPECT_NEAR(frames.back().second.at(0), 1.0, kEps);

  // The end is written once more, then the servo keeps it.
  const std::size_t written = frames.size();
  tickAt(101.1);
  tickAt(101.2);
  EXPECT_EQ(frames.size(), written + 1);
}

TEST_F(ExecutorRig, PathToleranceAbortHoldsWhereLastWritten) {
  GoalDefaults strict = defaults();
  strict.path_tolerance = 0.1;
  executor.retune(strict);
  measure({"arm_1"}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  measure({"arm_1"}, {0.2});
  tickAt(100.25);
  ASSERT_FALSE(log.over());
  EXPECT_NEAR(frames.back().second.at(0), 0.25, kEps);

  measure({"arm_1"}, {0.2});  // 0.3 rad behind
  tickAt(100.5);
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kAborted);
  EXPECT_EQ(log.outcome().error_code, result_code::kPathToleranceViolated);
  EXPECT_NE(log.outcome().text.find("path tolerance"), std::string::npos);
  EXPECT_EQ(log.outcome().error_string, log.outcome().text);
  EXPECT_EQ(warnings.back(), "follow_joint_trajectory: aborted: " + log.outcome().text);
  // Held at the last written position, not the measurement nor the spline.
  EXPECT_NEAR(frames.back().second.at(0), 0.25, kEps);
}

TEST_F(ExecutorRig, GoalTimeToleranceGivesTheJointsTimeToArrive) {
  measure({"arm_1"}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  for (double t : {100.5, 101.0, 101.3, 101.5}) {
    measure({"arm_1"}, {0.8});
    tickAt(t);
    ASSERT_FALSE(log.over()) << "at " << t;
  }
  measure({"arm_1"}, {0.8});
  tickAt(101.6);
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().error_code, result_code::kGoalToleranceViolated);
  EXPECT_NE(log.outcome().text.find("after the goal time tolerance"), std::string::npos);

  // A goal's own tolerance replaces the default; a negative one means none.
  Goal strict = goalTo({"arm_1"}, {1.0}, 1.0, "strict");
  strict.goal_time_tolerance = -1.0;
  GoalLog strict_log;
  executor.submitGoal(strict, strict_log.callbacks());
  now = 102.7;  // past its end (102.6), measured now
  measure({"arm_1"}, {0.8});
  executor.tick();
  ASSERT_TRUE(strict_log.over());
  EXPECT_EQ(strict_log.outcome().error_code, result_code::kGoalToleranceViolated);
}

TEST_F(ExecutorRig, NewGoalOrMessagePreemptsFromTheDesiredState) {
  measure({"arm_1", "arm_2"}, {0.0, 0.0});
  GoalLog first;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}, 1.0, "first"), first.callbacks());
  measure({"arm_1", "arm_2"}, {0.0, 0.0});
  tickAt(100.5);
  // A goal on other joints leaves it running.
  GoalLog other;
  executor.submitGoal(goalTo({"arm_2"}, {0.5}, 1.0, "other"), other.callbacks());
  EXPECT_FALSE(first.over());

  GoalLog second;
  executor.submitGoal(goalTo({"arm_1"}, {0.5}, 1.0, "second"), second.callbacks());
  ASSERT_TRUE(first.over());
  EXPECT_EQ(first.outcome().status, GoalStatus::kCanceled);
  EXPECT_EQ(first.outcome().error_code, result_code::kSuccessful);
  EXPECT_EQ(first.outcome().text, "preempted by a new goal");
  EXPECT_FALSE(second.over());
  // The bridge starts where arm_1 was meant to be (0.5), not where it is measured (0).
  tickAt(100.5);
  EXPECT_NEAR(frames.back().second.at(0), 0.5, kEps);

  TrajectoryCommand message;
  message.joint_names = {"arm_1"};
  message.points.push_back({1.0, {0.0}, {}, {}});
  executor.submitTrajectory(message, std::nullopt);
  ASSERT_TRUE(second.over());
  EXPECT_EQ(second.outcome().status, GoalStatus::kCanceled);
  EXPECT_EQ(second.outcome().text, "preempted by a joint_trajectory message");
  EXPECT_FALSE(other.over());
}

TEST_F(ExecutorRig, CancelHoldsEveryJointWhereItWasLastCommanded) {
  measure({"arm_1", "pan"}, {0.0, 0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1", "pan"}, {1.0, 1.0}, 1.0, "g"), log.callbacks());
  measure({"arm_1", "pan"}, {0.1, 0.1});
  tickAt(100.2);
  ASSERT_EQ(moves.size(), 1u);  // one move per segment, to its end in the time left
  EXPECT_NEAR(std::get<1>(moves[0]), 1.0, kEps);
  EXPECT_NEAR(std::get<2>(moves[0]), 0.8, kEps);
  const double written = frames.back().second.at(0);

  executor.cancelGoal("unknown");
  EXPECT_FALSE(log.over());
  executor.cancelGoal("g");
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kCanceled);
  EXPECT_EQ(log.outcome().error_code, result_code::kSuccessful);
  EXPECT_EQ(log.outcome().text, "cancelled: holding where they were last commanded");
  EXPECT_EQ(stops, std::vector<std::size_t>{0});  // the servo stops where it is, no move
  tickAt(100.3);
  EXPECT_NEAR(frames.back().second.at(0), written, kEps);
  EXPECT_EQ(moves.size(), 1u);
  executor.cancelGoal("g");  // over: nothing more
  EXPECT_EQ(log.outcomes.size(), 1u);
}

TEST_F(ExecutorRig, EmptyTrajectoryHoldsOrNamesTheJointsLeftAlone) {
  Goal stop;
  stop.id = "stop";
  stop.command.joint_names = {"arm_2", "pan"};
  GoalLog log;
  executor.submitGoal(stop, log.callbacks());
  ASSERT_TRUE(log.over());
  const std::string left_alone =
      "joints 'arm_2', 'pan' left alone: never commanded by the driver nor recently measured, so "
      "there is no position to hold";
  EXPECT_EQ(log.accepted, 1);
  EXPECT_EQ(log.outcome().status, GoalStatus::kSucceeded);
  EXPECT_EQ(log.outcome().error_string, left_alone);
  EXPECT_EQ(log.outcome().text, "stopped where they were last commanded; " + left_alone);
  tickAt(100.1);
  EXPECT_TRUE(frames.empty());
  EXPECT_TRUE(stops.empty());

  // The device's own last command is held when the executor never wrote the joint.
  body_last_commanded = 0.7;
  GoalLog held;
  stop.command.joint_names = {"arm_2"};
  executor.submitGoal(stop, held.callbacks());
  EXPECT_EQ(held.outcome().error_string, "");
  EXPECT_EQ(held.outcome().text, "stopped where they were last commanded");
  tickAt(100.2);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_NEAR(frames[0].second.at(0), 0.7, kEps);
}

TEST_F(ExecutorRig, StaleBusJointAbortsAndStopsItsServo) {
  measure({"pan"}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"pan"}, {1.0}, 2.0), log.callbacks());
  tickAt(100.4);
  EXPECT_FALSE(log.over());
  // A slower poll: the joint may go longer without an answer.
  executor.setStateTimeout({"pan", "not_a_joint"}, 1.0);
  tickAt(100.9);
  EXPECT_FALSE(log.over());
  tickAt(101.1);
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kAborted);
  EXPECT_EQ(log.outcome().error_code, result_code::kPathToleranceViolated);
  EXPECT_EQ(log.outcome().text,
            "telemetry lost: no state of joint 'pan' for more than 1.0 s, so nobody can tell "
            "whether it follows");
  EXPECT_EQ(stops, std::vector<std::size_t>{0});
}

// A device whose joints never change looks their tracks up once; its measurements by track keep
// exactly those joints fresh.
TEST_F(ExecutorRig, MeasurementsByTrackKeepTheirJointsFresh) {
  EXPECT_EQ(executor.tracksOf({"arm_2"}), std::vector<std::size_t>{1});
  const std::vector<std::size_t> tracks = executor.tracksOf({"not_a_joint", "pan"});
  EXPECT_EQ(tracks, (std::vector<std::size_t>{TrajectoryExecutor::kNoTrack, 2}));
  executor.setStateTimeout({"pan"}, 1.0);
  executor.updateActual(tracks, {5.0, 0.0}, {});
  GoalLog log;
  executor.submitGoal(goalTo({"pan"}, {1.0}, 2.0), log.callbacks());
  tickAt(100.9);
  executor.updateActual(tracks, {5.0, 0.4}, {});  // pan measured again at 100.9
  tickAt(101.5);
  EXPECT_FALSE(log.over());  // stale at 101.1 had the measurement gone to another joint
  tickAt(101.95);
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().error_code, result_code::kPathToleranceViolated);
  EXPECT_NE(log.outcome().text.find("no state of joint 'pan'"), std::string::npos);
}

TEST_F(ExecutorRig, TakeOverStopsTheTrajectoryOnlyWhenTheOtherCommandWrote) {
  measure({"arm_1"}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  executor.takeOver({"arm_1"}, "joint_commands", [] { return false; });
  EXPECT_FALSE(log.over());
  bool ran = false;
  executor.takeOver({"arm_1"}, "joint_commands", [&] { return ran = true; });
  EXPECT_TRUE(ran);
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kAborted);
  EXPECT_EQ(log.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(log.outcome().text, "joint 'arm_1' taken over by joint_commands: trajectory stopped");
  tickAt(100.5);
  EXPECT_TRUE(frames.empty());  // the other command's position stays
}

TEST_F(ExecutorRig, WriteErrorsAreLoggedAtMostOnceASecond) {
  write_error = "joint 'arm_1' out of range";
  measure({"arm_1"}, {0.0});
  TrajectoryCommand message;
  message.joint_names = {"arm_1"};
  message.points.push_back({5.0, {1.0}, {}, {}});
  executor.submitTrajectory(message, std::nullopt);
  for (double t = 100.1; t < 101.05; t += 0.1) tickAt(t);
  tickAt(101.2);
  EXPECT_EQ(warnings, std::vector<std::string>(2, "trajectory: joint 'arm_1' out of range"));
}

// The node's loop timer runs only while the executor has work: an idle node wakes no thread.
TEST_F(ExecutorRig, TheTickerRunsOnlyWhileThereIsWork) {
  std::vector<bool> switched;
  executor.setTicker([&switched](bool on) { switched.push_back(on); });
  tickAt(100.1);
  EXPECT_TRUE(switched.empty()) << "idle: never switched on";

  measure({"arm_1"}, {0.0}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  EXPECT_EQ(switched, std::vector<bool>{true});
  measure({"arm_1"}, {1.0});
  tickAt(101.0);  // reached
  ASSERT_TRUE(log.over());
  tickAt(101.1);  // the end written once more: nothing left to do
  EXPECT_EQ(switched, (std::vector<bool>{true, false}));
  tickAt(101.2);
  EXPECT_EQ(switched.size(), 2u);

  body_last_commanded = 0.7;
  Goal stop = goalTo({"arm_1"}, {1.0}, 1.0, "stop");
  stop.command.points.clear();  // an empty trajectory: a hold to write where the body last was
  GoalLog stop_log;
  executor.submitGoal(stop, stop_log.callbacks());
  ASSERT_TRUE(stop_log.over());
  EXPECT_EQ(stop_log.outcome().text, "stopped where they were last commanded");
  EXPECT_EQ(switched, (std::vector<bool>{true, false, true}));
  tickAt(101.3);
  EXPECT_EQ(switched, (std::vector<bool>{true, false, true, false}));

  executor.shutdown();
  GoalLog late;
  executor.submitGoal(goalTo({"arm_1"}, {0.0}, 1.0, "late"), late.callbacks());
  EXPECT_EQ(switched.size(), 4u) << "never switched once shut down";
}

}  // namespace
}  // namespace serial_robot_driver::trajectory
