// One joint's motion in time, ROS-free, interpolated as ros_control's joint_trajectory_controller
// does: each segment between two waypoints is linear when they give positions only, a cubic when
// they also give velocities, a quintic when they also give accelerations. Times are seconds on
// whatever clock the caller samples with (the ROS layer uses ROS time).
#pragma once

#include <optional>
#include <vector>

namespace serial_robot_driver::trajectory {

/// A joint's set-point: rad, rad/s, rad/s^2.
struct JointSample {
  double position = 0.0;
  double velocity = 0.0;
  double acceleration = 0.0;
};

/// What a waypoint specifies beyond its position; it chooses the segment's polynomial.
enum class Interpolation { kLinear, kCubic, kQuintic };

struct Waypoint {
  double time = 0.0;  ///< absolute, s
  JointSample sample;
  Interpolation order = Interpolation::kLinear;  ///< what sample holds: position (+vel (+acc))
};

/// A polynomial from (start_time, start) to (end_time, end) of the given order. Outside its span it
/// holds the nearest end's position at rest (velocity and acceleration 0).
class Segment {
 public:
  Segment(double start_time, const JointSample& start, double end_time, const JointSample& end,
          Interpolation order);
  JointSample sample(double time) const;
  double startTime() const { return start_time_; }
  double endTime() const { return end_time_; }
  /// Ends the segment early, at `time` (its polynomial is unchanged, later times hold there).
  void truncate(double time);

 private:
  JointSample evaluate(double time_in_segment) const;

  double start_time_;
  double end_time_;
  double coefficients_[6] = {0, 0, 0, 0, 0, 0};  ///< p(t) = sum c_i t^i, t from start_time_
};

/// Where a segment runs and where it ends.
struct SegmentSpan {
  double start_time = 0.0;
  double end_time = 0.0;
  JointSample end;
};

/// Segments back to back, or a position held when there are none.
class JointSpline {
 public:
  /// Holds `position` at rest until something is spliced in.
  explicit JointSpline(double position = 0.0) : hold_{position, 0.0, 0.0} {}

  /// Before the first segment: its start state at rest (a trajectory stamped in the future holds
  /// where it begins); after the last: its end at rest.
  JointSample sample(double time) const;
  /// The time of the last waypoint, or -infinity when only holding.
  double endTime() const;
  bool holding() const { return segments_.empty(); }
  /// The segment that runs at `time` (start <= time < end); nothing when none does.
  std::optional<SegmentSpan> segmentAt(double time) const;

  /// Replaces what follows `from` by a bridge from this spline's own state at `from` to the first
  /// waypoint, then the waypoints' segments: what already ran is kept, so there is no jump.
  /// `waypoints` must be in increasing time, none before `from` (a waypoint at `from` is a zero
  /// length bridge: the joint goes there at once). Empty `waypoints`: hold the state at `from`.
  void splice(double from, const std::vector<Waypoint>& waypoints);
  /// Forgets segments that ended before `time` (sampling at or after `time` is unchanged).
  void prune(double time);

 private:
  JointSample hold_;
  std::vector<Segment> segments_;
};

}  // namespace serial_robot_driver::trajectory
