// The trajectory executor without ROS, when a command starts and what an e-stop does: a start
// stamped too far ahead is refused, a late stamp bridges in the command's own time; an e-stop
// aborts, holds and refuses, and voids what was accepted before it. Time is a number the tests
// step by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/trajectory/executor.h"
#include "support/trajectory_executor_rig.h"

namespace serial_robot_driver::trajectory {
namespace {

using test::ExecutorRig;
using test::GoalLog;
using test::kEps;

TEST_F(ExecutorRig, AStartFurtherAheadThanMaxStartDelayIsRefused) {
  using Submission = TrajectoryExecutor::Submission;
  measure({"arm_1"}, {0.0});
  // 10 s by default: a stamp in the far future (4e9 s since 1970 is 2.3e9 s ahead) would
  // otherwise hold the joints for decades.
  for (const double ahead : {10.5, 2.3e9, std::numeric_limits<double>::quiet_NaN()}) {
    Goal goal = goalTo({"arm_1"}, {0.5});
    goal.start_time = now + ahead;
    GoalLog log;
    EXPECT_EQ(executor.submitGoal(goal, log.callbacks()), Submission::kInvalid) << ahead;
    ASSERT_TRUE(log.over());
    EXPECT_EQ(log.accepted, 0);
    EXPECT_EQ(log.outcome().error_code, result_code::kInvalidGoal);
    EXPECT_NE(log.outcome().error_string.find("later than max_start_delay 10 s"), std::string::npos)
        << log.outcome().error_string;
    EXPECT_EQ(executor.submitTrajectory(goal.command, now + ahead), Submission::kInvalid);
  }
  tickAt(now + 0.1);
  EXPECT_TRUE(frames.empty()) << "nothing refused moves";

  Goal soon = goalTo({"arm_1"}, {0.5});
  soon.start_time = now + 9.5;
  GoalLog accepted;
  EXPECT_EQ(executor.submitGoal(soon, accepted.callbacks()), Submission::kAccepted);
  EXPECT_EQ(accepted.accepted, 1);

  GoalDefaults patient = defaults();
  patient.max_start_delay = 20.0;
  executor.retune(patient);
  EXPECT_EQ(executor.submitTrajectory(goalTo({"arm_2"}, {0.5}).command, now + 15.0),
            Submission::kInvalid)
      << "arm_2 was never measured";
  measure({"arm_2"}, {0.0});
  EXPECT_EQ(executor.submitTrajectory(goalTo({"arm_2"}, {0.5}).command, now + 15.0),
            Submission::kAccepted);
}

TEST_F(ExecutorRig, ALateStampBridgesInTheCommandsOwnTimeNeverInAJump) {
  // max_velocity 0 (no limit to refuse a fast bridge). Stamped 1 s ago, first point 1.05 s after
  // the stamp: joint_trajectory_controller would leave 0.05 s to go 1 rad. The bridge gets the
  // point's own 1.05 s, as if the goal were stamped now.
  measure({"arm_1"}, {0.0});
  Goal late = goalTo({"arm_1"}, {1.0}, 1.05);
  late.start_time = now - 1.0;
  GoalLog log;
  executor.submitGoal(late, log.callbacks());
  ASSERT_EQ(log.accepted, 1);
  tickAt(100.05);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_NEAR(frames[0].second.at(0), 0.05 / 1.05, 1e-6) << "linear from now over 1.05 s";
  measure({"arm_1"}, {0.5});
  tickAt(100.525);
  EXPECT_NEAR(frames.back().second.at(0), 0.5, 1e-6);
  EXPECT_FALSE(log.over()) << "it ends 1.05 s from now, not 0.05 s";

  // A message too, and the rest of the command keeps its own timing after the bridge.
  measure({"arm_2"}, {0.0});
  TrajectoryCommand command;
  command.joint_names = {"arm_2"};
  command.points = {{0.5, {0.2}, {}, {}}, {1.5, {1.2}, {}, {}}, {2.0, {1.2}, {}, {}}};
  // Stamped 1.4 s ago: the first point is past, 0.1 s left to the second (planned 1 s after it).
  executor.submitTrajectory(command, now - 1.4);
  measure({"arm_1", "arm_2"}, {0.5, 0.6});
  tickAt(now + 0.5);
  EXPECT_NEAR(frames.back().first.back() == "arm_2" ? frames.back().second.back() : -1.0, 0.6, 1e-6)
      << "from 0 to 1.2 rad in 1 s: halfway after 0.5 s";
}

TEST_F(ExecutorRig, EStopAbortsHoldsAndRefuses) {
  core::EStop e_stop;
  executor.attachEStop(e_stop);
  measure({"arm_1"}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  measure({"arm_1"}, {0.2});
  tickAt(100.25);
  const double written = frames.back().second.at(0);

  e_stop.set(true);
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kAborted);
  EXPECT_EQ(log.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(log.outcome().text, "e_stop engaged");
  tickAt(100.5);
  EXPECT_NEAR(frames.back().second.at(0), written, kEps);  // held, not followed on

  GoalLog refused;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), refused.callbacks());
  EXPECT_EQ(refused.outcome().status, GoalStatus::kRejected);
  EXPECT_EQ(refused.outcome().error_code, result_code::kInvalidGoal);
  EXPECT_EQ(refused.outcome().text, "e_stop is engaged");
  TrajectoryCommand message;
  message.joint_names = {"arm_1"};
  message.points.push_back({1.0, {1.0}, {}, {}});
  const std::size_t warned = warnings.size();
  executor.submitTrajectory(message, std::nullopt);
  executor.submitTrajectory(message, std::nullopt);  // within a second: counted, not logged
  EXPECT_EQ(warnings.size(), warned + 1);
  EXPECT_EQ(warnings.back(), "joint_trajectory: message ignored, nothing moves: e_stop is engaged");
  EXPECT_EQ(e_stop.stats().refused.at("follow_joint_trajectory"), 1u);
  EXPECT_EQ(e_stop.stats().refused.at("joint_trajectory"), 2u);
}

// An e-stop voids everything accepted before it: a goal, or a joint_trajectory still waiting for
// its start, accepted before an e-stop that was engaged and released between two ticks never
// moves a joint after the release; the goal is aborted, saying why.
TEST_F(ExecutorRig, TrajectoriesAcceptedBeforeAnEStopNeverMoveAfterItsRelease) {
  core::EStop e_stop;
  executor.attachEStop(e_stop);
  // As the node's body: its gate starts a new generation after the trajectories stopped.
  e_stop.addListener([this](bool engaged) { body_generation += engaged ? 1 : 0; });
  measure({"arm_1", "arm_2"}, {0.0, 0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}), log.callbacks());
  TrajectoryCommand later;  // starts in 0.5 s: queued
  later.joint_names = {"arm_2"};
  later.points.push_back({1.0, {1.0}, {}, {}});
  executor.submitTrajectory(later, now + 0.5);
  tickAt(100.1);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frame_generations.back(), std::optional<uint64_t>(0));

  e_stop.set(true);
  e_stop.set(false);  // no tick while it held
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kAborted);
  for (double t = 100.2; t < 102.0; t += 0.1) tickAt(t);
  // Whatever was tried after the release was voided (the rig's gate writes nothing for it).
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_EQ(frame_generations[i], std::optional<uint64_t>(0)) << "frame " << i;
  }
  EXPECT_LE(frames.size(), 2u) << "at most the hold was tried once, and voided";
  EXPECT_EQ(executor.motionInForce(), "");
}

// The motion question a sensor calibration asks once per frame (inMotion) agrees with the text it
// asks for (motionInForce) through a goal's life, a bare trajectory, a joint taken over and a stop.
TEST_F(ExecutorRig, InMotionAgreesWithMotionInForceAtEveryStep) {
  const auto expectMoving = [this](bool moving, const char* when) {
    EXPECT_EQ(executor.inMotion(), moving) << when;
    EXPECT_EQ(!executor.motionInForce().empty(), moving)
        << when << ": " << executor.motionInForce();
  };
  measure({"arm_1", "arm_2"}, {0.0, 0.0});
  expectMoving(false, "idle");
  GoalLog log;
  executor.submitGoal(goalTo({"arm_2"}, {0.5}, 1.0), log.callbacks());
  expectMoving(true, "a goal accepted");
  for (double t = 100.1; t < 100.95; t += 0.1) {
    tickAt(t);
    ASSERT_FALSE(frames.empty());
    measure({"arm_2"}, {frames.back().second.at(0)});  // it follows
    expectMoving(true, "a goal running");
  }
  measure({"arm_2"}, {0.5});
  for (double t = 101.0; t < 101.45; t += 0.1) tickAt(t);
  ASSERT_TRUE(log.over()) << "the goal ended";
  EXPECT_EQ(log.outcome().status, GoalStatus::kSucceeded);
  expectMoving(false, "the goal over and its last position written");

  using Submission = TrajectoryExecutor::Submission;
  measure({"arm_1", "arm_2"}, {0.0, 0.5});
  ASSERT_EQ(executor.submitTrajectory(goalTo({"arm_1"}, {0.2}, 1.0).command, std::nullopt),
            Submission::kAccepted);
  expectMoving(true, "a trajectory without a goal");
  executor.takeOver({"arm_1"}, "joint_commands", [] { return true; });
  expectMoving(false, "taken over by joint_commands");

  GoalLog stopped;
  ASSERT_EQ(executor.submitGoal(goalTo({"arm_1", "arm_2"}, {0.3, 0.3}, 1.0), stopped.callbacks()),
            Submission::kAccepted);
  tickAt(101.6);
  executor.stopAll("test stop");
  ASSERT_TRUE(stopped.over());
  EXPECT_EQ(stopped.outcome().status, GoalStatus::kAborted);
  expectMoving(true, "held: written once more");
  tickAt(101.7);
  tickAt(101.8);
  expectMoving(false, "the hold written");
}

// The e-stop's hook missed (an e-stop engaged while the executor was writing): the device's gate
// voids the frame, and the executor drops the trajectory and aborts its goal instead of retrying.
TEST_F(ExecutorRig, AFrameTheGateVoidedDropsItsTrajectory) {
  measure({"arm_1"}, {0.0});
  GoalLog log;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}, 2.0), log.callbacks());
  EXPECT_EQ(executor.motionInForce(), "trajectory in progress ('arm_1')");
  during_write = [this] { body_generation = 1; };  // engaged (and released) meanwhile
  tickAt(100.1);
  during_write = nullptr;
  ASSERT_TRUE(log.over());
  EXPECT_EQ(log.outcome().status, GoalStatus::kAborted);
  EXPECT_EQ(log.outcome().text,
            "trajectory of joint 'arm_1' dropped: e-stop engaged after this command was accepted");
  const std::size_t tried = frames.size();
  tickAt(100.2);
  tickAt(100.3);
  EXPECT_EQ(frames.size(), tried) << "never written again";
  EXPECT_EQ(executor.motionInForce(), "");

  // A trajectory accepted after it moves.
  GoalLog fresh;
  executor.submitGoal(goalTo({"arm_1"}, {1.0}, 2.0), fresh.callbacks());
  tickAt(100.4);
  EXPECT_EQ(frame_generations.back(), std::optional<uint64_t>(1));
  EXPECT_FALSE(fresh.over());
}

}  // namespace
}  // namespace serial_robot_driver::trajectory
