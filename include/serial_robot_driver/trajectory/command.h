// A joint trajectory as a goal or a joint_trajectory message gives it, ROS-free: checked whole
// before anything moves, then turned into one spline per joint.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "serial_robot_driver/trajectory/spline.h"

namespace serial_robot_driver::trajectory {

struct TrajectoryPoint {
  double time_from_start = 0.0;    ///< s, from the command's start time
  std::vector<double> positions;   ///< rad, one per joint
  std::vector<double> velocities;  ///< empty, or one per joint
  std::vector<double> accelerations;  ///< empty, or one per joint
};

struct TrajectoryCommand {
  std::vector<std::string> joint_names;
  std::vector<TrajectoryPoint> points;
};

/// A joint the driver can move, and the positions its servo can reach (rad).
struct JointRange {
  std::string name;
  double min_position = 0.0;
  double max_position = 0.0;
};

/// The result codes of control_msgs/FollowJointTrajectoryResult that validation can give.
enum class CommandError { kNone, kInvalidJoints, kInvalidGoal, kOldTimestamp };

struct CommandCheck {
  CommandError error = CommandError::kNone;
  std::string message;  ///< names the joint and the point
  /// For each command joint, its index in the `joints` validate() was given.
  std::vector<std::size_t> joint_indices;

  bool ok() const { return error == CommandError::kNone; }
};

/// Checks a command against the joints the driver has.
///  - unknown or duplicate joint names -> kInvalidJoints;
///  - a point whose positions / velocities / accelerations do not match the joints in number,
///    NaN or infinity, times that are negative or do not increase, a position the servo cannot
///    reach, a velocity or a speed between points above `max_velocity` (0: no limit) -> kInvalidGoal.
/// `start_offset` (s) is the command's start time minus now, `current_positions` the joints'
/// desired positions now (in command order; empty: not checked): with max_velocity they check the
/// bridge to the first point that is not in the past. When every point is in the past:
/// kOldTimestamp. An empty point list is valid: it means "stop where you are".
CommandCheck validate(const TrajectoryCommand& command, const std::vector<JointRange>& joints,
                      double max_velocity, double start_offset = 0.0,
                      const std::vector<double>& current_positions = {});

/// The waypoints of the command's joint `column` (its index in joint_names), in absolute time:
/// start_time + time_from_start, leaving out the points not after `now` (joint_trajectory
/// _controller drops them). The command must have passed validate().
std::vector<Waypoint> waypointsFor(const TrajectoryCommand& command, std::size_t column,
                                   double start_time, double now);

}  // namespace serial_robot_driver::trajectory
