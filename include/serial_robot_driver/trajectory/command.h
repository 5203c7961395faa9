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

/// When a command stamped to start at `start` really starts, received at `now` (one clock, s).
/// A start not in the past is kept. A start in the past is taken as joint_trajectory_controller
/// takes it (the points already past are dropped, the rest keep their spacing), except that the
/// bridge from the joints' current set-point to the first point still ahead never gets less time
/// than the command itself planned for reaching that point (its time_from_start when it is the
/// first point, the gap from the point before it otherwise): the whole command starts that much
/// later. In effect the segment running now is run whole from now (the first one: the command as
/// if stamped now), so a late stamp never squeezes the bridge into a jump, with or without a
/// ~trajectory/max_velocity to refuse one. Every point in the past: `start` (validate() refuses).
double effectiveStart(const TrajectoryCommand& command, double start, double now);

/// The waypoints of the command's joint `column` (its index in joint_names), in absolute time:
/// start_time + time_from_start, leaving out the points not after `now` (joint_trajectory
/// _controller drops them). The command must have passed validate().
std::vector<Waypoint> waypointsFor(const TrajectoryCommand& command, std::size_t column,
                                   double start_time, double now);

}  // namespace serial_robot_driver::trajectory
