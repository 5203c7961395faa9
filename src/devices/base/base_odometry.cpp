#include "serial_robot_driver/devices/base/base_odometry.h"

#include <algorithm>
#include <chrono>

#include "serial_robot_driver/core/clock.h"
#include "serial_robot_driver/devices/base/base_controller.h"

namespace serial_robot_driver::devices::base {

using kinematics::WheelSpeeds;

BaseOdometry::BaseOdometry(const BaseConfig& config)
    : geometry_(config.geometry),
      heartbeat_gap_(config.heartbeat_gap),
      use_imu_heading_(config.use_imu_heading),
      imu_yaw_variance_(config.imu_yaw_variance),
      odometry_(config.geometry.wheel_separation, config.odometry_covariance),
      heading_(config.imu_stale_after) {}

void BaseOdometry::advance(core::Clock::time_point now) {
  double dt = 0;
  if (accepted_at_) {
    // The base runs the last accepted speeds until its heartbeat timeout stops it.
    const core::Clock::time_point end =
        std::min(now, *accepted_at_ + core::fromSeconds(heartbeat_gap_));
    if (end > integrated_until_) {
      dt = core::toSeconds(end - integrated_until_);
      wheel_travel_ += held_speeds_ * dt;
      integrated_until_ = end;
    }
  }
  // The fused heading follows the IMU even while the wheels stand still (the robot was pushed).
  const std::optional<double> heading =
      use_imu_heading_ ? heading_.heading(now, odometry_.pose().yaw) : std::nullopt;
  if (heading) {
    odometry_.integrate(held_speeds_, dt, *heading, imu_yaw_variance_);
  } else if (dt > 0) {
    odometry_.integrate(held_speeds_, dt);
  }
}

void BaseOdometry::speedAccepted(const kinematics::WheelTicks& ticks, core::Clock::time_point now) {
  advance(now);
  const double per_tick = 1.0 / geometry_.ticksPerPeriodPerMps();
  held_speeds_ = WheelSpeeds(ticks.left * per_tick, ticks.right * per_tick);
  accepted_at_ = now;
  integrated_until_ = now;
}

void BaseOdometry::baseStopped(core::Clock::time_point now) {
  advance(now);
  held_speeds_.setZero();
}

void BaseOdometry::reset(core::Clock::time_point now) {
  advance(now);
  odometry_.reset();
  if (use_imu_heading_) {
    heading_.restart();
    advance(now);  // anchors the IMU's yaw now at heading zero, if it is fresh
  }
}

void BaseOdometry::retune(const kinematics::DiffDriveGeometry& geometry, bool use_imu_heading,
                          core::Clock::time_point now) {
  // The motion so far, and the wheel angles so far, with the geometry they ran under.
  advance(now);
  wheel_angles_at_retune_ += (wheel_travel_ - travel_at_retune_) / (geometry_.wheel_diameter / 2.0);
  travel_at_retune_ = wheel_travel_;
  // The base goes on running the ticks it accepted last; with the new geometry they stand for
  // other speeds (a corrected diameter is the truth about what the wheels did all along).
  held_speeds_ *= geometry_.ticksPerPeriodPerMps() / geometry.ticksPerPeriodPerMps();
  geometry_ = geometry;
  odometry_.setWheelSeparation(geometry.wheel_separation);
  if (use_imu_heading != use_imu_heading_) {
    // On: anchored where odometry stands now; off: the commanded turn goes on from the last fused
    // heading. Either way the heading does not jump.
    if (use_imu_heading) heading_.restart();
    use_imu_heading_ = use_imu_heading;
  }
}

OdometrySample BaseOdometry::sample(core::Clock::time_point now) const {
  OdometrySample sample;
  sample.time = now;
  sample.pose = odometry_.pose();
  const bool running = accepted_at_ && core::toSeconds(now - *accepted_at_) < heartbeat_gap_;
  if (running) {
    sample.linear = (held_speeds_.x() + held_speeds_.y()) / 2.0;
    sample.angular = (held_speeds_.y() - held_speeds_.x()) / geometry_.wheel_separation;
    sample.wheel_speeds = held_speeds_;
  }
  sample.wheel_travel = wheel_travel_;
  const double radius = geometry_.wheel_diameter / 2.0;
  sample.wheel_angles = wheel_angles_at_retune_ + (wheel_travel_ - travel_at_retune_) / radius;
  sample.wheel_rates = sample.wheel_speeds / radius;
  sample.position_variance = odometry_.positionVariance();
  sample.yaw_variance = odometry_.yawVariance();
  sample.travelled = odometry_.travelled();
  sample.imu_heading = use_imu_heading_ && heading_.source() == kinematics::HeadingSource::kImu;
  return sample;
}

void BaseOdometry::addImuYaw(double yaw, core::Clock::time_point stamp) {
  // Stored even while use_imu_heading is off (addSample only copies two values under its own
  // lock): use_imu_heading_ belongs to the controller's lock, and a retune may switch the fusion
  // on at any time.
  heading_.addSample(yaw, stamp);
}

void BaseOdometry::addHeadingStats(BaseStats& stats, core::Clock::time_point now) const {
  if (!use_imu_heading_) return;
  stats.heading_source = heading_.source();
  stats.imu_heading_fallbacks = heading_.fallbacks();
  stats.imu_yaw_age = heading_.sampleAge(now);
}

std::optional<kinematics::HeadingSource> BaseOdometry::headingSourceChange() {
  if (!use_imu_heading_ || heading_.source() == reported_heading_source_) return std::nullopt;
  reported_heading_source_ = heading_.source();
  return reported_heading_source_;
}

}  // namespace serial_robot_driver::devices::base
