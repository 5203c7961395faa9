// The AP1 base's odometry: the pose, the wheels' travel and angles and the pose covariance, from
// the wheel speeds of each speed frame the base accepted, integrated from its write until the next
// accepted frame, the base's own heartbeat timeout, or an FF error, whichever comes first. With
// use_imu_heading the heading comes from kinematics::HeadingFusion while the IMU yaw is fresh.
//
// Not thread-safe: BaseController owns it and calls every member with its own mutex_ held (the
// odometry moves with the frames written under that lock). The one exception is addImuYaw(), which
// any thread may call: it only hands the sample to HeadingFusion (its own short lock), so the IMU
// telemetry never waits for a base write.
#pragma once

#include <optional>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/kinematics/diff_drive.h"
#include "serial_robot_driver/kinematics/heading_fusion.h"
#include "serial_robot_driver/kinematics/odometry.h"

namespace serial_robot_driver::devices::base {

// Defined in base_controller.h, the controller's public interface.
struct BaseConfig;
struct BaseStats;
struct OdometrySample;

class BaseOdometry {
 public:
  /// Uses geometry, heartbeat_gap, odometry_covariance and the IMU heading settings of `config`.
  explicit BaseOdometry(const BaseConfig& config);

  /// Integrates the speeds the base runs on up to `now` (capped at its heartbeat timeout). A fused
  /// heading follows the IMU even while the wheels stand still.
  void advance(core::Clock::time_point now);
  /// A speed frame with these (robot-side, before wheel directions) ticks was accepted at `now`.
  void speedAccepted(const kinematics::WheelTicks& ticks, core::Clock::time_point now);
  /// The yaw variance (rad^2) of the IMU's heading, while it is fused.
  void setImuYawVariance(double variance) { imu_yaw_variance_ = variance; }
  /// The base reported its timeout error at `now`: it has stopped its wheels.
  void baseStopped(core::Clock::time_point now);
  /// Puts the pose (and its covariance) back to zero at `now`; a fused heading restarts at zero.
  void reset(core::Clock::time_point now);
  /// From `now` on: `geometry` (the speeds the base holds are re-read through it), and
  /// use_imu_heading. The motion and the wheel angles up to `now` keep the geometry they ran
  /// under; the pose does not jump.
  void retune(const kinematics::DiffDriveGeometry& geometry, bool use_imu_heading,
              core::Clock::time_point now);

  /// Where the odometry stands at `now` (call advance() first).
  OdometrySample sample(core::Clock::time_point now) const;

  /// Any thread: the yaw (rad) of the IMU on the base, measured at `stamp`.
  void addImuYaw(double yaw, core::Clock::time_point stamp);
  /// With use_imu_heading: fills the heading fields of `stats` (source, fallbacks, IMU yaw age).
  void addHeadingStats(BaseStats& stats, core::Clock::time_point now) const;
  /// With use_imu_heading: the heading's source, when it changed since the last call.
  std::optional<kinematics::HeadingSource> headingSourceChange();

 private:
  kinematics::DiffDriveGeometry geometry_;  ///< changes in retune()
  const double heartbeat_gap_;              ///< s
  bool use_imu_heading_;
  double imu_yaw_variance_;  ///< changes in setImuYawVariance()
  kinematics::Odometry odometry_;
  kinematics::HeadingFusion heading_;  ///< used with use_imu_heading only
  kinematics::HeadingSource reported_heading_source_ = kinematics::HeadingSource::kWaitingForImu;
  kinematics::WheelSpeeds held_speeds_ = kinematics::WheelSpeeds::Zero();   ///< the base runs these
  kinematics::WheelSpeeds wheel_travel_ = kinematics::WheelSpeeds::Zero();  ///< see OdometrySample
  /// Wheel angles and travel when the diameter last changed (see OdometrySample::wheel_angles).
  kinematics::WheelSpeeds wheel_angles_at_retune_ = kinematics::WheelSpeeds::Zero();
  kinematics::WheelSpeeds travel_at_retune_ = kinematics::WheelSpeeds::Zero();
  std::optional<core::Clock::time_point> accepted_at_;  ///< last speed frame the base accepted
  core::Clock::time_point integrated_until_{};
};

}  // namespace serial_robot_driver::devices::base
