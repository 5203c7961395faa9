#include "serial_robot_driver/trajectory/command_start.h"

#include <algorithm>
#include <cstdio>
#include <iterator>

namespace serial_robot_driver::trajectory {

double effectiveStart(const TrajectoryCommand& command, double start, double now) {
  if (!(start < now)) return start;
  const auto& points = command.points;
  const auto first_ahead =
      std::find_if(points.begin(), points.end(),
                   [&](const TrajectoryPoint& p) { return start + p.time_from_start > now; });
  if (first_ahead == points.end()) return start;
  const double planned =
      first_ahead == points.begin()
          ? first_ahead->time_from_start
          : first_ahead->time_from_start - std::prev(first_ahead)->time_from_start;
  const double left = start + first_ahead->time_from_start - now;
  return left < planned ? start + (planned - left) : start;
}

std::optional<double> startOf(const TrajectoryCommand& command, std::optional<double> start_time,
                              double now, double max_start_delay, CommandCheck* refusal) {
  if (!start_time) return now;
  // NaN fails this test too; the ROS layer never gives one, the check is for any other caller.
  if (!(*start_time - now <= max_start_delay)) {
    refusal->error = CommandError::kInvalidGoal;
    char text[200];
    std::snprintf(text, sizeof(text),
                  "its start (header.stamp) is %.3g s from now, later than max_start_delay %.3g s",
                  *start_time - now, max_start_delay);
    refusal->message = text;
    return std::nullopt;
  }
  return effectiveStart(command, *start_time, now);
}

}  // namespace serial_robot_driver::trajectory
