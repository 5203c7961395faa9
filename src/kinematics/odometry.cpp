#include "serial_robot_driver/kinematics/odometry.h"

#include <cmath>

namespace serial_robot_driver::kinematics {
namespace {
// Below this heading change per step the arc radius v / w is numerically unreliable.
constexpr double kStraightStepYaw = 1e-6;
}  // namespace

Odometry::Odometry(double wheel_separation, PoseCovarianceModel model)
    : wheel_separation_(wheel_separation), model_(model) {}

void Odometry::integrate(const WheelSpeeds& speeds, double dt) {
  if (!std::isfinite(dt) || dt < 0 || !speeds.allFinite()) return;
  linear_ = (speeds.x() + speeds.y()) / 2.0;
  angular_ = (speeds.y() - speeds.x()) / wheel_separation_;
  const double distance = linear_ * dt;
  const double turn = angular_ * dt;
  if (std::abs(turn) < kStraightStepYaw) {
    const double mid_yaw = pose_.yaw + turn / 2.0;
    pose_.x += distance * std::cos(mid_yaw);
    pose_.y += distance * std::sin(mid_yaw);
  } else {
    const double radius = linear_ / angular_;
    const double new_yaw = pose_.yaw + turn;
    pose_.x += radius * (std::sin(new_yaw) - std::sin(pose_.yaw));
    pose_.y -= radius * (std::cos(new_yaw) - std::cos(pose_.yaw));
  }
  pose_.yaw = std::remainder(pose_.yaw + turn, 2.0 * M_PI);
  travelled_ += (std::abs(speeds.x()) + std::abs(speeds.y())) / 2.0 * dt;
}

void Odometry::reset() {
  pose_ = Pose2D{};
  linear_ = angular_ = travelled_ = 0;
}

double Odometry::positionVariance() const {
  return model_.initial_position_variance + model_.position_variance_per_meter * travelled_;
}

double Odometry::yawVariance() const {
  return model_.initial_yaw_variance + model_.yaw_variance_per_meter * travelled_;
}

}  // namespace serial_robot_driver::kinematics
