// The trajectory executor without ROS: goals accepted or rejected (with the action's codes and
// texts), the splines sampled each tick, path and goal tolerances, the goal time tolerance,
// preemption, what a cancel, an e-stop or lost telemetry holds, and take-overs. Time is a number
// the tests step by hand.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "serial_robot_driver/device/e_stop.h"
#include "serial_robot_driver/trajectory/executor.h"

namespace serial_robot_driver::trajectory {
namespace {

constexpr double kEps = 1e-9;

/// What a goal was told.
struct GoalLog {
  int accepted = 0;
  std::vector<GoalFeedback> feedback;
  std::vector<GoalOutcome> outcomes;

  GoalCallbacks callbacks() {
    return {[this] { ++accepted; }, [this](const GoalFeedback& f) { feedback.push_back(f); },
            [this](const GoalOutcome& o) { outcomes.push_back(o); }};
  }
  bool over() const { return !outcomes.empty(); }
  const GoalOutcome& outcome() const { return outcomes.at(0); }
};

/// Two streamed joints (arm_1, arm_2: the body) and one per-segment joint (pan: a bus servo),
/// every call they get recorded, on a clock at 100 s.
class ExecutorRig : public ::testing::Test {
 protected:
  using Frame = std::pair<std::vector<std::string>, std::vector<double>>;

  ExecutorRig()
      : executor(
            groups(), defaults(), [this] { return now; }, warner()) {
    executor.start();
  }

  static GoalDefaults defaults() {
    GoalDefaults d;
    d.goal_tolerance = 0.05;
    d.goal_time_tolerance = 0.5;
    return d;
  }

  std::vector<TrajectoryJoints> groups() {
    TrajectoryJoints body;
    body.joints = {{"arm_1", -3.0, 3.0}, {"arm_2", -3.0, 3.0}};
    body.write = [this](const std::vector<std::string>& names, const std::vector<double>& p,
                        std::optional<uint64_t> accepted) {
      if (during_write) during_write();
      frames.emplace_back(names, p);
      frame_generations.push_back(accepted);
      // As the body's gate: a frame accepted before the last e-stop is not written.
      if (accepted && *accepted != body_generation) return std::string("voided");
      return write_error;
    };
    body.generation = [this] { return body_generation; };
    body.last_commanded = [this](std::size_t) { return body_last_commanded; };
    TrajectoryJoints bus;
    bus.joints = {{"pan", -3.0, 3.0}};
    bus.move = [this](std::size_t index, double position, double duration) {
      moves.emplace_back(index, position, duration);
      return std::string();
    };
    bus.stop = [this](std::size_t index) {
      stops.push_back(index);
      return std::string();
    };
    return {body, bus};
  }

  TrajectoryExecutor::Warn warner() {
    return [this](const std::string& text) { warnings.push_back(text); };
  }

  void measure(const std::vector<std::string>& names, const std::vector<double>& positions,
               const std::vector<double>& velocities = {}) {
    executor.updateActual(names, positions, velocities);
  }

  /// A goal moving `names` to `positions` in `seconds`, starting at once.
  static Goal goalTo(const std::vector<std::string>& names, const std::vector<double>& positions,
                     double seconds = 1.0, const std::string& id = "g") {
    Goal goal;
    goal.id = id;
    goal.command.joint_names = names;
    goal.command.points.push_back({seconds, positions, {}, {}});
    return goal;
  }

  /// Steps the clock to `time`, then ticks.
  void tickAt(double time) {
    now = time;
    executor.tick();
  }

  double now = 100.0;
  uint64_t body_generation = 0;        ///< the body gate's e-stop generation
  std::function<void()> during_write;  ///< runs inside each body write
  std::vector<Frame> frames;
  std::vector<std::optional<uint64_t>> frame_generations;  ///< what each frame was written with
  std::string write_error;
  std::optional<double> body_last_commanded;
  std::vector<std::tuple<std::size_t, double, double>> moves;
  std::vector<std::size_t> stops;
  std::vector<std::string> warnings;
  TrajectoryExecutor executor;
};

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

TEST_F(ExecutorRig, EStopAbortsHoldsAndRefuses) {
  device::EStop e_stop;
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
  device::EStop e_stop;
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

}  // namespace
}  // namespace serial_robot_driver::trajectory
