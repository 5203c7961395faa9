// Differential-drive kinematics for the AP1 base: cmd_vel -> wheel speeds (m/s) -> encoder ticks
// per PID period, the unit of the base's speed frame. Eigen carries the left/right pairs.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace serial_robot_driver::kinematics {

/// (left, right), m/s.
using WheelSpeeds = Eigen::Vector2d;

struct DiffDriveGeometry {
  double wheel_diameter = 0.25;      ///< m
  double wheel_separation = 0.40;    ///< m, between the wheel contact points
  double encoder_resolution = 1600;  ///< ticks per wheel revolution
  double pid_rate = 50;              ///< Hz, the base's speed-control period

  double ticksPerMeter() const;
  /// Ticks per PID period for 1 m/s.
  double ticksPerPeriodPerMps() const { return ticksPerMeter() / pid_rate; }
};

/// Body twist (linear.x m/s, angular.z rad/s) to wheel speeds.
WheelSpeeds wheelSpeedsFromTwist(const DiffDriveGeometry& geometry, double linear_x,
                                 double angular_z);

/// Scales both wheels by the same factor so that neither exceeds `max_wheel_speed`: the turn radius
/// (the ratio between the wheels) is kept. `max_wheel_speed` must be > 0: there is no "no limit"
/// value, and a limit that is not > 0 (0, negative, NaN) stops both wheels.
WheelSpeeds clampWheelSpeeds(const WheelSpeeds& speeds, double max_wheel_speed);

/// Limits how fast each wheel's speed may change. Both wheels are scaled by the same fraction of
/// their requested change, so the path curvature is kept while ramping.
class AccelerationLimiter {
 public:
  /// `max_accel` in m/s^2; 0 means no limit.
  explicit AccelerationLimiter(double max_accel) : max_accel_(max_accel) {}
  /// Moves from the last output toward `target` within `dt` seconds and returns the new output.
  WheelSpeeds step(const WheelSpeeds& target, double dt);
  void reset(const WheelSpeeds& current = WheelSpeeds::Zero()) { current_ = current; }
  const WheelSpeeds& current() const { return current_; }
  /// A new limit from the next step on; the speeds reached so far are kept (no jump).
  void setMaxAccel(double max_accel) { max_accel_ = max_accel; }

 private:
  double max_accel_;
  WheelSpeeds current_ = WheelSpeeds::Zero();
};

struct WheelTicks {
  int16_t left = 0;
  int16_t right = 0;
  bool operator==(const WheelTicks& other) const {
    return left == other.left && right == other.right;
  }
};

/// Wheel speeds (m/s) to integer ticks per PID period.
///  - dithering on: the fractional remainder is carried to the next period (error feedback), so the
///    mean over many periods equals the exact speed (0.02 m/s -> 0.815 ticks on average, not 0);
///  - dithering off: the vendor's truncation toward zero, `int(v * ticks_per_meter / PID_RATE)`.
/// Values beyond int16 saturate.
class TickQuantizer {
 public:
  TickQuantizer(const DiffDriveGeometry& geometry, bool dithering);
  WheelTicks quantize(const WheelSpeeds& speeds);
  /// Forgets the carried remainder (after a reconnect or a stop).
  void reset() { remainder_.setZero(); }
  /// Exact ticks per period that `speeds` stand for (no rounding).
  Eigen::Vector2d exactTicks(const WheelSpeeds& speeds) const;
  /// New geometry or dithering from the next quantize() on. The carried remainder (under one
  /// tick) is kept while dithering stays on, forgotten when it is switched off.
  void retune(const DiffDriveGeometry& geometry, bool dithering);

 private:
  double ticks_per_period_per_mps_;
  bool dithering_;
  Eigen::Vector2d remainder_ = Eigen::Vector2d::Zero();
};

}  // namespace serial_robot_driver::kinematics
