// When a command (a goal or a joint_trajectory message) starts, ROS-free: a start stamped too far
// ahead is refused, a start in the past is moved so the bridge to the command never becomes a jump.
#pragma once

#include <optional>

#include "serial_robot_driver/trajectory/command.h"

namespace serial_robot_driver::trajectory {

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

/// The start on which `command`, stamped `start_time` (nothing: now), runs: effectiveStart();
/// nothing, with `refusal` set, when it is further ahead than `max_start_delay` (s; or not a time).
std::optional<double> startOf(const TrajectoryCommand& command, std::optional<double> start_time,
                              double now, double max_start_delay, CommandCheck* refusal);

}  // namespace serial_robot_driver::trajectory
