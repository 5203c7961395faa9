#include "serial_robot_driver/kinematics/diff_drive.h"

#include <cmath>
#include <limits>

namespace serial_robot_driver::kinematics {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInt16Max = std::numeric_limits<int16_t>::max();
constexpr double kInt16Min = std::numeric_limits<int16_t>::min();

// A NaN or an infinity from a misbehaving publisher must never reach the motors: treat it as
// "stop". (An infinity let through would turn into NaN in the clamp: inf * (max / inf).)
double finiteOrZero(double value) { return std::isfinite(value) ? value : 0.0; }

WheelSpeeds sanitized(const WheelSpeeds& speeds) {
  return WheelSpeeds(finiteOrZero(speeds.x()), finiteOrZero(speeds.y()));
}

// Clamps to the int16 range first so the cast is always defined (also for +-inf and NaN).
int16_t saturateToInt16(double ticks) {
  if (std::isnan(ticks)) return 0;
  if (ticks >= kInt16Max) return std::numeric_limits<int16_t>::max();
  if (ticks <= kInt16Min) return std::numeric_limits<int16_t>::min();
  return static_cast<int16_t>(ticks);
}

bool exceedsInt16(double ticks) { return ticks > kInt16Max || ticks < kInt16Min; }

}  // namespace

double DiffDriveGeometry::ticksPerMeter() const {
  return encoder_resolution / (kPi * wheel_diameter);
}

WheelSpeeds wheelSpeedsFromTwist(const DiffDriveGeometry& geometry, double linear_x,
                                 double angular_z) {
  const double v = finiteOrZero(linear_x);
  const double half_turn = finiteOrZero(angular_z) * geometry.wheel_separation / 2.0;
  return WheelSpeeds(v - half_turn, v + half_turn);
}

WheelSpeeds clampWheelSpeeds(const WheelSpeeds& speeds, double max_wheel_speed) {
  const WheelSpeeds clean = sanitized(speeds);
  if (!(max_wheel_speed > 0.0)) return WheelSpeeds::Zero();  // invalid: never "no limit"
  const double largest = clean.cwiseAbs().maxCoeff();
  if (largest <= max_wheel_speed) return clean;
  return clean * (max_wheel_speed / largest);
}

WheelSpeeds AccelerationLimiter::step(const WheelSpeeds& target, double dt) {
  if (!(dt > 0.0)) return current_;
  const WheelSpeeds clean_target = sanitized(target);
  if (!(max_accel_ > 0.0)) {
    current_ = clean_target;
    return current_;
  }
  const WheelSpeeds change = clean_target - current_;
  const double largest_change = change.cwiseAbs().maxCoeff();
  const double allowed_change = max_accel_ * dt;
  // One common fraction for both wheels keeps the ratio of their changes, hence the curvature.
  const double fraction = largest_change > allowed_change ? allowed_change / largest_change : 1.0;
  current_ += change * fraction;
  return current_;
}

TickQuantizer::TickQuantizer(const DiffDriveGeometry& geometry, bool dithering)
    : ticks_per_period_per_mps_(geometry.ticksPerPeriodPerMps()), dithering_(dithering) {}

void TickQuantizer::retune(const DiffDriveGeometry& geometry, bool dithering) {
  ticks_per_period_per_mps_ = geometry.ticksPerPeriodPerMps();
  dithering_ = dithering;
  if (!dithering_) remainder_.setZero();
}

Eigen::Vector2d TickQuantizer::exactTicks(const WheelSpeeds& speeds) const {
  return sanitized(speeds) * ticks_per_period_per_mps_;
}

WheelTicks TickQuantizer::quantize(const WheelSpeeds& speeds) {
  const Eigen::Vector2d exact = exactTicks(speeds);
  if (!dithering_) {
    // The vendor's int(): truncation toward zero.
    return WheelTicks{saturateToInt16(std::trunc(exact.x())),
                      saturateToInt16(std::trunc(exact.y()))};
  }

  const Eigen::Vector2d wanted = exact + remainder_;
  Eigen::Vector2d sent;
  for (int wheel = 0; wheel < 2; ++wheel) {
    if (exact[wheel] == 0.0) {
      // A stop is a stop: a carried +-0.5 would otherwise round to +1, -1, +1 ... forever.
      sent[wheel] = 0;
      remainder_[wheel] = 0.0;
      continue;
    }
    const double rounded = std::round(wanted[wheel]);
    if (exceedsInt16(rounded) || !std::isfinite(rounded)) {
      // Saturated: the shortfall can never be paid back, so carrying it would only wind up.
      sent[wheel] = saturateToInt16(rounded);
      remainder_[wheel] = 0.0;
    } else {
      sent[wheel] = rounded;
      remainder_[wheel] = wanted[wheel] - rounded;
    }
  }
  return WheelTicks{static_cast<int16_t>(sent.x()), static_cast<int16_t>(sent.y())};
}

}  // namespace serial_robot_driver::kinematics
