// Path and goal tolerances as joint_trajectory_controller applies them, ROS-free.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/trajectory/spline.h"

namespace serial_robot_driver::trajectory {

/// The defaults of goals and messages; the ~trajectory/... rows bind straight to these fields
/// (params::TrajectoryParams).
struct GoalDefaults {
  double goal_tolerance = 0.05;      ///< rad, per joint
  double goal_time_tolerance = 0.5;  ///< s after the last point's time to get within goal_tolerance
  double path_tolerance = 0.0;       ///< rad; 0: not checked
  double max_velocity = 0.0;         ///< rad/s per joint; faster is refused; 0: no limit
  /// s; a command whose start (header.stamp) is further ahead of now than this is refused, so a
  /// stamp in the far future cannot pin the joints until then. > 0.
  double max_start_delay = 10.0;
};

/// How far a joint may be from its set-point; 0: not checked. Acceleration is never checked: the
/// servos report no acceleration.
struct JointTolerance {
  double position = 0.0;  ///< rad
  double velocity = 0.0;  ///< rad/s
};

/// One entry of a goal's tolerance list.
struct NamedTolerance {
  std::string name;
  double position = 0.0;
  double velocity = 0.0;
};

/// A goal's value over the default, per control_msgs/JointTolerance: 0 keeps the default, a
/// negative value (-1) removes the check, a positive value replaces the default.
double overrideTolerance(double default_value, double goal_value);

/// Per joint of `joints`: `defaults`, overridden by the entries of `overrides` naming that joint
/// (entries naming other joints are ignored, as joint_trajectory_controller does).
std::vector<JointTolerance> resolveTolerances(const std::vector<std::string>& joints,
                                              const JointTolerance& defaults,
                                              const std::vector<NamedTolerance>& overrides);

struct ToleranceViolation {
  std::size_t joint = 0;  ///< index into the checked joints
  std::string message;    ///< "joint 'x': position error 0.2 rad is beyond the path tolerance 0.1 rad"
};

/// The first joint whose actual state is beyond its tolerance of the desired one. `what` names the
/// tolerance in the message ("path", "goal").
std::optional<ToleranceViolation> findViolation(const std::vector<std::string>& joints,
                                                const std::vector<JointTolerance>& tolerances,
                                                const std::vector<JointSample>& desired,
                                                const std::vector<JointSample>& actual,
                                                const char* what);

}  // namespace serial_robot_driver::trajectory
