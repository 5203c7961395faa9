// A follow_joint_trajectory goal, ROS-free, apart from the executor (executor.h) that runs it: the
// goal as submitted and as it runs, what it is told (the action's result codes, how it ended, its
// feedback, the callbacks that carry them), and the helpers that end goals and build their texts.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/trajectory/command.h"
#include "serial_robot_driver/trajectory/spline.h"
#include "serial_robot_driver/trajectory/tolerances.h"

namespace serial_robot_driver::trajectory {

/// A follow_joint_trajectory goal.
struct Goal {
  std::string id;  ///< what cancelGoal() names it by
  TrajectoryCommand command;
  std::optional<double> start_time;  ///< on the executor's clock; nothing: at once
  std::vector<NamedTolerance> path_tolerance;
  std::vector<NamedTolerance> goal_tolerance;
  double goal_time_tolerance = 0.0;  ///< s; 0: the default; negative: none
};

/// control_msgs/FollowJointTrajectoryResult's error codes (the ROS layer checks they agree).
namespace result_code {
constexpr int kSuccessful = 0;
constexpr int kInvalidGoal = -1;
constexpr int kInvalidJoints = -2;
constexpr int kOldHeaderTimestamp = -3;
constexpr int kPathToleranceViolated = -4;
constexpr int kGoalToleranceViolated = -5;
}  // namespace result_code

enum class GoalStatus { kRejected, kSucceeded, kCanceled, kAborted };

/// How a goal ended: its result (error_code, error_string) and the status text.
struct GoalOutcome {
  GoalStatus status = GoalStatus::kSucceeded;
  int error_code = result_code::kSuccessful;
  std::string error_string;
  std::string text;
};

/// A running goal's state, once per tick; velocities of `actual` and `error` are empty unless
/// every joint's velocity is measured.
struct GoalFeedback {
  std::vector<std::string> joint_names;
  double time_from_start = 0.0;  ///< s since the goal's start (0 before it)
  std::vector<JointSample> desired;
  std::vector<double> actual_positions;
  std::vector<double> actual_velocities;
  std::vector<double> error_positions;
  std::vector<double> error_velocities;
};

/// What a goal tells its client; all may be empty. Called with the executor's lock held.
struct GoalCallbacks {
  std::function<void()> accepted;  ///< before anything else that is told of an accepted goal
  std::function<void(const GoalFeedback&)> feedback;
  std::function<void(const GoalOutcome&)> finished;  ///< rejected or ended; once
};

/// A goal accepted and running: its joints (track indices), tolerances and times (executor clock).
struct ActiveGoal {
  std::string id;
  GoalCallbacks callbacks;
  std::vector<std::size_t> joints;
  std::vector<std::string> names;
  std::vector<JointTolerance> path_tolerances;
  std::vector<JointTolerance> goal_tolerances;
  double start_time = 0.0;
  double end_time = 0.0;
  double goal_time_tolerance = 0.0;
};

/// The running goal `goal` becomes, on the executor's `joints` from `start`, with `defaults`.
ActiveGoal admitGoal(const Goal& goal, GoalCallbacks callbacks,
                     const std::vector<std::size_t>& joints, double start,
                     const GoalDefaults& defaults);

/// Ends the goals that drive any of `joints` with `status`, `code` and `message`.
void endGoalsOn(std::vector<ActiveGoal>& goals, const std::vector<std::size_t>& joints,
                GoalStatus status, int code, const std::string& message);

/// The result code of a command that failed its check with `error`.
int resultCode(CommandError error);

GoalOutcome outcome(GoalStatus status, int code, const std::string& error_string,
                    const std::string& text);

/// The outcome whose result and status text are both `message`.
GoalOutcome outcome(GoalStatus status, int code, const std::string& message);

/// Tells the goal's client `result` (when it listens).
void finish(const GoalCallbacks& callbacks, const GoalOutcome& result);

/// "; joint 'a', 'b' left alone: ..." for the joints a stop could not hold, "" when none.
std::string leftAloneText(const std::vector<std::string>& names);

/// `message`, then `; left_alone` when there is one.
std::string withLeftAlone(const std::string& message, const std::string& left_alone);

}  // namespace serial_robot_driver::trajectory
