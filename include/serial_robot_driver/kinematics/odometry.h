// Dead-reckoning of a differential-drive base from wheel speeds held over known intervals.
//
// The AP1 reports no encoder counts, so the driver feeds this with the wheel speeds it commanded
// and the base accepted: the pose is commanded motion, not a measurement. Its covariance therefore
// only grows (open loop) with the distance the wheels travelled, see PoseCovarianceModel.
#pragma once

#include "serial_robot_driver/kinematics/diff_drive.h"

namespace serial_robot_driver::kinematics {

/// Planar pose in the odometry frame: m, m, rad (counter-clockwise, wrapped to [-pi, pi]).
struct Pose2D {
  double x = 0;
  double y = 0;
  double yaw = 0;
};

/// How the pose variance grows: a random walk in the distance travelled, as an open-loop estimate
/// must (nothing ever corrects it). `travelled` is the mean of both wheels' absolute paths, so a
/// turn on the spot counts too.
///   var(x) = var(y) = initial_position_variance + position_variance_per_meter * travelled
///   var(yaw)        = initial_yaw_variance + yaw_variance_per_meter * travelled
/// A measured heading (Odometry::integrate with measured_yaw) restarts var(yaw) from the
/// measurement's variance; it grows per metre again from there once measurements stop.
struct PoseCovarianceModel {
  double initial_position_variance = 1e-6;      ///< m^2
  double position_variance_per_meter = 0.0025;  ///< m^2 per m: std 5 cm after 1 m, 16 cm after 10 m
  double initial_yaw_variance = 1e-6;           ///< rad^2
  double yaw_variance_per_meter = 0.01;         ///< rad^2 per m: std 0.1 rad after 1 m
};

class Odometry {
 public:
  explicit Odometry(double wheel_separation, PoseCovarianceModel model = {});

  /// Advances the pose by wheel speeds (left, right; m/s) held for `dt` s. Exact circular arc;
  /// for a nearly straight step (|angular * dt| tiny, where the arc formula divides by almost 0)
  /// the second-order Runge-Kutta (midpoint) step, as ros_controllers' diff_drive_controller does.
  /// Non-finite or negative `dt`, or non-finite speeds, leave the pose unchanged.
  void integrate(const WheelSpeeds& speeds, double dt);
  /// Like integrate(), but the heading at the end of the step is `measured_yaw` (an IMU's) rather
  /// than the commanded turn: the path is the arc through the measured turn, as long as the
  /// commanded distance. The yaw variance becomes `measured_yaw_variance` and grows from there
  /// again (per metre, as the model says) over the steps that follow without a measurement.
  /// dt = 0 only sets the heading. A non-finite argument leaves the pose unchanged.
  void integrate(const WheelSpeeds& speeds, double dt, double measured_yaw,
                 double measured_yaw_variance);
  /// Pose, distance travelled and twist back to zero.
  void reset();
  /// A corrected wheel separation for the steps from now on; the pose reached so far is kept.
  void setWheelSeparation(double wheel_separation) { wheel_separation_ = wheel_separation; }
  double wheelSeparation() const { return wheel_separation_; }

  const Pose2D& pose() const { return pose_; }
  /// Body twist of the speeds last given to integrate() (m/s, rad/s).
  double linear() const { return linear_; }
  double angular() const { return angular_; }
  /// Mean absolute wheel path since the last reset (m).
  double travelled() const { return travelled_; }
  double positionVariance() const;
  double yawVariance() const;

 private:
  /// Moves `distance` along the arc that turns the heading by `turn` (rad).
  void step(double distance, double turn);

  double wheel_separation_;
  PoseCovarianceModel model_;
  Pose2D pose_;
  double linear_ = 0;
  double angular_ = 0;
  double travelled_ = 0;
  // The yaw variance grows from this value at this distance travelled (the last measured heading).
  double yaw_variance_origin_;
  double yaw_travelled_origin_ = 0;
};

}  // namespace serial_robot_driver::kinematics
