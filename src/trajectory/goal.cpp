#include "serial_robot_driver/trajectory/goal.h"

#include <algorithm>

namespace serial_robot_driver::trajectory {

namespace {

bool overlaps(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) {
  return std::any_of(a.begin(), a.end(),
                     [&](std::size_t j) { return std::find(b.begin(), b.end(), j) != b.end(); });
}

}  // namespace

ActiveGoal admitGoal(const Goal& goal, GoalCallbacks callbacks,
                     const std::vector<std::size_t>& joints, double start,
                     const GoalDefaults& defaults) {
  ActiveGoal active;
  active.id = goal.id;
  active.callbacks = std::move(callbacks);
  active.joints = joints;
  active.names = goal.command.joint_names;
  const JointTolerance path_defaults{defaults.path_tolerance, 0.0};
  const JointTolerance goal_defaults{defaults.goal_tolerance, 0.0};
  active.path_tolerances = resolveTolerances(active.names, path_defaults, goal.path_tolerance);
  active.goal_tolerances = resolveTolerances(active.names, goal_defaults, goal.goal_tolerance);
  active.start_time = start;
  active.end_time = start + goal.command.points.back().time_from_start;
  active.goal_time_tolerance = goal.goal_time_tolerance == 0.0
                                   ? defaults.goal_time_tolerance
                                   : std::max(0.0, goal.goal_time_tolerance);
  return active;
}

void endGoalsOn(std::vector<ActiveGoal>& goals, const std::vector<std::size_t>& joints,
                GoalStatus status, int code, const std::string& message) {
  for (auto it = goals.begin(); it != goals.end();) {
    if (!overlaps(it->joints, joints)) {
      ++it;
      continue;
    }
    finish(it->callbacks, outcome(status, code, message));
    it = goals.erase(it);
  }
}

int resultCode(CommandError error) {
  switch (error) {
    case CommandError::kNone:
      return result_code::kSuccessful;
    case CommandError::kInvalidJoints:
      return result_code::kInvalidJoints;
    case CommandError::kInvalidGoal:
      return result_code::kInvalidGoal;
    case CommandError::kOldTimestamp:
      return result_code::kOldHeaderTimestamp;
  }
  return result_code::kInvalidGoal;
}

GoalOutcome outcome(GoalStatus status, int code, const std::string& error_string,
                    const std::string& text) {
  return {status, code, error_string, text};
}

GoalOutcome outcome(GoalStatus status, int code, const std::string& message) {
  return outcome(status, code, message, message);
}

void finish(const GoalCallbacks& callbacks, const GoalOutcome& result) {
  if (callbacks.finished) callbacks.finished(result);
}

std::string leftAloneText(const std::vector<std::string>& names) {
  if (names.empty()) return "";
  std::string text = names.size() == 1 ? "joint " : "joints ";
  for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", '" : "'") + names[i] + "'";
  return text +
         " left alone: never commanded by the driver nor recently measured, so there is no "
         "position to hold";
}

std::string withLeftAlone(const std::string& message, const std::string& left_alone) {
  if (left_alone.empty()) return message;
  return message.empty() ? left_alone : message + "; " + left_alone;
}

}  // namespace serial_robot_driver::trajectory
