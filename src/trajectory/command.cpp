#include "serial_robot_driver/trajectory/command.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <iterator>
#include <unordered_set>

namespace serial_robot_driver::trajectory {

namespace {

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char text[256];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(text, sizeof(text), fmt, args);
  va_end(args);
  return text;
}

CommandCheck failure(CommandError error, std::string message) {
  CommandCheck check;
  check.error = error;
  check.message = std::move(message);
  return check;
}

/// "point 2 has 3 velocities for 2 joints", or empty when `values` fits.
std::string sizeProblem(const std::vector<double>& values, std::size_t joints, std::size_t point,
                        const char* what, bool may_be_empty) {
  if (values.size() == joints || (may_be_empty && values.empty())) return {};
  return format("point %zu has %zu %s for %zu joints", point, values.size(), what, joints);
}

/// The index in `joints` of every command joint; kInvalidJoints when one is unknown or repeated.
CommandCheck resolveJoints(const TrajectoryCommand& command,
                           const std::vector<JointRange>& joints) {
  CommandCheck check;
  const std::vector<std::string>& names = command.joint_names;
  if (names.empty() && !command.points.empty()) {
    return failure(CommandError::kInvalidJoints, "the trajectory names no joint");
  }
  std::unordered_set<std::string> seen;
  for (const std::string& name : names) {
    auto joint = std::find_if(joints.begin(), joints.end(),
                              [&](const JointRange& j) { return j.name == name; });
    if (joint == joints.end()) {
      return failure(CommandError::kInvalidJoints, "unknown joint '" + name + "'");
    }
    if (!seen.insert(name).second) {
      return failure(CommandError::kInvalidJoints, "joint '" + name + "' is named more than once");
    }
    check.joint_indices.push_back(static_cast<std::size_t>(joint - joints.begin()));
  }
  return check;
}

/// Point p's value counts against the n joints and its time after the previous point's; "" if fine.
std::string pointShapeProblem(const TrajectoryCommand& command, std::size_t p, std::size_t n) {
  const TrajectoryPoint& point = command.points[p];
  for (const std::string& problem :
       {sizeProblem(point.positions, n, p, "positions", false),
        sizeProblem(point.velocities, n, p, "velocities", true),
        sizeProblem(point.accelerations, n, p, "accelerations", true)}) {
    if (!problem.empty()) return problem;
  }
  if (!std::isfinite(point.time_from_start) || point.time_from_start < 0.0) {
    return format("point %zu: time_from_start %g s is not a time from the start", p,
                  point.time_from_start);
  }
  if (p > 0 && point.time_from_start <= command.points[p - 1].time_from_start) {
    return format("point %zu: time_from_start %g s is not after point %zu's %g s", p,
                  point.time_from_start, p - 1, command.points[p - 1].time_from_start);
  }
  return {};
}

/// Command joint j at point p: finite, within `range`, and (max_velocity > 0) neither its velocity
/// nor the speed from the previous point above max_velocity; "" if fine.
std::string jointValueProblem(const TrajectoryCommand& command, std::size_t p, std::size_t j,
                              const JointRange& range, double max_velocity) {
  const TrajectoryPoint& point = command.points[p];
  const char* name = command.joint_names[j].c_str();
  const double position = point.positions[j];
  const double velocity = point.velocities.empty() ? 0.0 : point.velocities[j];
  const double acceleration = point.accelerations.empty() ? 0.0 : point.accelerations[j];
  if (!std::isfinite(position) || !std::isfinite(velocity) || !std::isfinite(acceleration)) {
    return format("joint '%s', point %zu: NaN or infinite value", name, p);
  }
  if (position < range.min_position || position > range.max_position) {
    return format("joint '%s', point %zu: %.4f rad is outside what it can reach (%.4f .. %.4f rad)",
                  name, p, position, range.min_position, range.max_position);
  }
  if (max_velocity <= 0.0) return {};
  if (std::abs(velocity) > max_velocity) {
    return format("joint '%s', point %zu: velocity %.4f rad/s is above max_velocity %.4f rad/s",
                  name, p, velocity, max_velocity);
  }
  if (p == 0) return {};
  const TrajectoryPoint& previous = command.points[p - 1];
  const double speed = std::abs(position - previous.positions[j]) /
                       (point.time_from_start - previous.time_from_start);
  if (speed > max_velocity) {
    return format(
        "joint '%s', point %zu: reaching it from point %zu takes %.4f rad/s, above "
        "max_velocity %.4f rad/s",
        name, p, p - 1, speed, max_velocity);
  }
  return {};
}

/// The bridge from `current_positions` to `first_ahead`, the first point not in the past: no
/// joint faster than max_velocity; "" if fine.
std::string bridgeProblem(const TrajectoryCommand& command, const TrajectoryPoint& first_ahead,
                          double max_velocity, double start_offset,
                          const std::vector<double>& current_positions) {
  // Held until the start when stamped ahead, so the bridge lasts the first point's own time.
  const double duration = first_ahead.time_from_start + std::min(start_offset, 0.0);
  const std::size_t p = static_cast<std::size_t>(&first_ahead - command.points.data());
  for (std::size_t j = 0; j < current_positions.size(); ++j) {
    const double distance = std::abs(first_ahead.positions[j] - current_positions[j]);
    if (distance > 0.0 && (duration <= 0.0 || distance / duration > max_velocity)) {
      return format(
          "joint '%s', point %zu: reaching it from where the joint is (%.4f rad) in "
          "%.3f s is faster than max_velocity %.4f rad/s",
          command.joint_names[j].c_str(), p, current_positions[j], duration, max_velocity);
    }
  }
  return {};
}

}  // namespace

CommandCheck validate(const TrajectoryCommand& command, const std::vector<JointRange>& joints,
                      double max_velocity, double start_offset,
                      const std::vector<double>& current_positions) {
  CommandCheck check = resolveJoints(command, joints);
  if (!check.ok()) return check;
  const std::size_t n = command.joint_names.size();
  for (std::size_t p = 0; p < command.points.size(); ++p) {
    std::string problem = pointShapeProblem(command, p, n);
    for (std::size_t j = 0; j < n && problem.empty(); ++j) {
      problem = jointValueProblem(command, p, j, joints[check.joint_indices[j]], max_velocity);
    }
    if (!problem.empty()) return failure(CommandError::kInvalidGoal, problem);
  }

  // The first point still ahead: where the bridge from the current state goes.
  const auto first_ahead =
      std::find_if(command.points.begin(), command.points.end(),
                   [&](const TrajectoryPoint& point) { return start_offset + point.time_from_start > 0.0; });
  if (!command.points.empty() && first_ahead == command.points.end()) {
    return failure(CommandError::kOldTimestamp,
                   format("every point is in the past (the last one %.3f s ago)",
                          -(start_offset + command.points.back().time_from_start)));
  }
  if (max_velocity > 0.0 && current_positions.size() == n && first_ahead != command.points.end()) {
    const std::string problem =
        bridgeProblem(command, *first_ahead, max_velocity, start_offset, current_positions);
    if (!problem.empty()) return failure(CommandError::kInvalidGoal, problem);
  }
  return check;
}

std::vector<Waypoint> waypointsFor(const TrajectoryCommand& command, std::size_t column,
                                   double start_time, double now) {
  std::vector<Waypoint> waypoints;
  for (const TrajectoryPoint& point : command.points) {
    const double time = start_time + point.time_from_start;
    if (time <= now) continue;
    Waypoint waypoint;
    waypoint.time = time;
    waypoint.sample.position = point.positions[column];
    if (!point.velocities.empty()) {
      waypoint.sample.velocity = point.velocities[column];
      waypoint.order = Interpolation::kCubic;
      if (!point.accelerations.empty()) {
        waypoint.sample.acceleration = point.accelerations[column];
        waypoint.order = Interpolation::kQuintic;
      }
    }
    waypoints.push_back(waypoint);
  }
  return waypoints;
}

}  // namespace serial_robot_driver::trajectory
