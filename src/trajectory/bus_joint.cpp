#include "serial_robot_driver/trajectory/bus_joint.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::trajectory {

namespace {
constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr double kServoLimitDeg = 180.0;  // single-turn angles
}  // namespace

double BusJoint::toServoDegrees(double radians) const {
  return zero_deg + direction * radians * kDegreesPerRadian;
}

double BusJoint::toRadians(double servo_degrees) const {
  return direction * (servo_degrees - zero_deg) / kDegreesPerRadian;
}

JointRange BusJoint::range() const {
  const double a = toRadians(-kServoLimitDeg);
  const double b = toRadians(kServoLimitDeg);
  return {name, std::min(a, b), std::max(a, b)};
}

std::optional<SegmentMove> segmentMoveAt(const JointSpline& spline, double now,
                                         double already_sent) {
  const std::optional<SegmentSpan> span = spline.segmentAt(now);
  if (!span || span->start_time == already_sent) return std::nullopt;
  return SegmentMove{span->end.position, span->end_time - now, span->start_time};
}

}  // namespace serial_robot_driver::trajectory
