#include "serial_robot_driver/kinematics/odometry.h"

#include <cmath>

namespace serial_robot_driver::kinematics {
namespace {
// Below this heading change per step the arc radius (distance / turn) is numerically unreliable.
constexpr double kStraightStepYaw = 1e-6;
}  // namespace

Odometry::Odometry(double wheel_separation, PoseCovarianceModel model)
    : wheel_separation_(wheel_separation),
      model_(model),
      yaw_variance_origin_(model.initial_yaw_variance) {}

void Odometry::integrate(const WheelSpeeds& speeds, double dt) {
  if (!std::isfinite(dt) || dt < 0 || !speeds.allFinite()) return;
  linear_ = (speeds.x() + speeds.y()) / 2.0;
  angular_ = (speeds.y() - speeds.x()) / wheel_separation_;
  step(linear_ * dt, angular_ * dt);
  travelled_ += (std::abs(speeds.x()) + std::abs(speeds.y())) / 2.0 * dt;
}

void Odometry::integrate(const WheelSpeeds& speeds, double dt, double measured_yaw,
                         double measured_yaw_variance) {
  if (!std::isfinite(dt) || dt < 0 || !speeds.allFinite() || !std::isfinite(measured_yaw) ||
      !std::isfinite(measured_yaw_variance)) {
    return;
  }
  linear_ = (speeds.x() + speeds.y()) / 2.0;
  angular_ = (speeds.y() - speeds.x()) / wheel_separation_;
  step(linear_ * dt, std::remainder(measured_yaw - pose_.yaw, 2.0 * M_PI));
  travelled_ += (std::abs(speeds.x()) + std::abs(speeds.y())) / 2.0 * dt;
  yaw_variance_origin_ = measured_yaw_variance;
  yaw_travelled_origin_ = travelled_;
}

void Odometry::step(double distance, double turn) {
  if (std::abs(turn) < kStraightStepYaw) {
    const double mid_yaw = pose_.yaw + turn / 2.0;
    pose_.x += distance * std::cos(mid_yaw);
    pose_.y += distance * std::sin(mid_yaw);
  } else {
    const double radius = distance / turn;
    const double new_yaw = pose_.yaw + turn;
    pose_.x += radius * (std::sin(new_yaw) - std::sin(pose_.yaw));
    pose_.y -= radius * (std::cos(new_yaw) - std::cos(pose_.yaw));
  }
  pose_.yaw = std::remainder(pose_.yaw + turn, 2.0 * M_PI);
}

void Odometry::reset() {
  pose_ = Pose2D{};
  linear_ = angular_ = travelled_ = 0;
  yaw_variance_origin_ = model_.initial_yaw_variance;
  yaw_travelled_origin_ = 0;
}

double Odometry::positionVariance() const {
  return model_.initial_position_variance + model_.position_variance_per_meter * travelled_;
}

double Odometry::yawVariance() const {
  return yaw_variance_origin_ +
         model_.yaw_variance_per_meter * (travelled_ - yaw_travelled_origin_);
}

}  // namespace serial_robot_driver::kinematics
