// A UART bus servo used as a named joint (~servo_bus/joint_ids ...), ROS-free: the map between the
// joint's position (rad) and the servo's angle (deg), and how a trajectory segment becomes one
// move of the servo.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/trajectory/command.h"
#include "serial_robot_driver/trajectory/spline.h"

namespace serial_robot_driver::trajectory {

struct BusJoint {
  uint8_t id = 0;
  std::string name;
  double zero_deg = 0.0;  ///< servo angle at joint position 0
  int direction = 1;      ///< +1 or -1

  /// servo angle = zero_deg + direction * position in degrees.
  double toServoDegrees(double radians) const;
  double toRadians(double servo_degrees) const;
  /// What a single-turn servo can reach (-180 .. 180 deg), in joint radians.
  JointRange range() const;
};

/// One move of a bus servo: to `position` (rad) in `duration` (s).
struct SegmentMove {
  double position = 0.0;
  double duration = 0.0;
  double segment_start = 0.0;  ///< which segment it is (pass it back as `already_sent`)
};

/// The move a bus servo gets at `now` for the segment of `spline` that runs then: to the segment's
/// end, in the time left to it. Nothing when no segment runs at `now` (holding, not started, over)
/// or when the segment that runs starts at `already_sent` (its move went out).
std::optional<SegmentMove> segmentMoveAt(const JointSpline& spline, double now,
                                         double already_sent);

}  // namespace serial_robot_driver::trajectory
