// The ServoBus's motion operations with their bookkeeping: which servos the driver set moving or
// positioned, so the e-stop and the shutdown can stop exactly those; relax and hold. The stops
// themselves are in servo_bus_stops.cpp.
#include <algorithm>
#include <cstdio>

#include "serial_robot_driver/device/servo_bus.h"

namespace serial_robot_driver::device {

namespace {

constexpr uint8_t kBroadcastId = 255;

std::string servoLabel(uint8_t id) { return "servo " + std::to_string(id); }

}  // namespace

void ServoBus::noteCommanded(uint8_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  commanded_.insert(id);
  stops_.erase(id);  // the gate was open: the e-stop is not engaged, this was a hold's stop
}

void ServoBus::noteMotion(uint8_t id, bool moving) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (moving) {
    moving_.insert(id);
  } else if (id == kBroadcastId) {
    moving_.clear();  // a broadcast stop or relax reached every servo
  } else {
    moving_.erase(id);
  }
}

ServoStatus ServoBus::refuseWhileLocked(uint8_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (motion_locked_) {
    return {ServoError::kMotionRefused,
            "e_stop is engaged: " + servoLabel(id) + " does not move until it is released"};
  }
  for (const HealthServo& servo : health_) {
    if (servo.report.id != id || !servo.report.overheated) continue;
    const ServoHealthReport& report = servo.report;
    return {ServoError::kMotionRefused,
            servoLabel(id) + " is relaxed: its temperature reached its over_temperature limit (" +
                std::to_string(report.readings.temperature_c) + " degC, limit " +
                std::to_string(report.limits.over_temperature_c) + " degC); moves are refused " +
                "until it has cooled to " +
                std::to_string(report.limits.over_temperature_c - OverheatGuard::kCoolDownC) +
                " degC"};
  }
  return {};
}

ServoStatus ServoBus::move(const MoveRequest& request) {
  ServoStatus status = refuseWhileLocked(request.id);
  if (!status.ok()) return status;
  status = client_.move(request);
  if (status.ok()) noteMotion(request.id, true);
  return status;
}

ServoStatus ServoBus::rotate(const RotateRequest& request) {
  ServoStatus status = refuseWhileLocked(request.id);
  if (!status.ok()) return status;
  status = client_.rotate(request);
  if (status.ok()) noteMotion(request.id, true);
  return status;
}

ServoStatus ServoBus::spin(const SpinRequest& request) {
  // A SPIN stop is always let through: it is what the e-stop itself sends.
  const bool stop = request.mode == 0;
  ServoStatus status = stop ? ServoStatus{} : refuseWhileLocked(request.id);
  if (!status.ok()) return status;
  status = client_.spin(request);
  if (status.ok()) noteMotion(request.id, !stop);
  return status;
}

ServoStatus ServoBus::damping(uint8_t id, uint16_t power_mw, bool wait) {
  ServoStatus status = refuseWhileLocked(id);
  if (!status.ok()) return status;
  status = client_.damping(id, power_mw, wait);
  if (status.ok()) {
    noteMotion(id, false);  // no holding torque: nothing keeps it moving or in place
    std::lock_guard<std::mutex> lock(mutex_);
    if (!motion_locked_) {
      commanded_.erase(id);
      stops_.erase(id);  // relaxed: there is nothing left to stop
    }
  }
  return status;
}

ServoStatus ServoBus::relax(const std::vector<uint8_t>& ids) {
  const std::vector<uint8_t>& targets = ids.empty() ? config_.polled_ids : ids;
  if (targets.empty()) {
    return {ServoError::kInvalidArgument, "no servo given and none configured (state_ids, joint_ids)"};
  }
  const uint16_t power_mw = settings().relax_power_mw;
  for (uint8_t id : targets) {
    const ServoStatus status = damping(id, power_mw, false);
    if (!status.ok()) return status;
  }
  return {ServoError::kOk, std::to_string(targets.size()) + " servo(s) relaxed (DAMPING " +
                               std::to_string(power_mw) + " mW)"};
}

ServoStatus ServoBus::hold(const std::vector<uint8_t>& ids) {
  const std::vector<uint8_t>& targets = ids.empty() ? config_.polled_ids : ids;
  if (targets.empty()) {
    return {ServoError::kInvalidArgument, "no servo given and none configured (state_ids, joint_ids)"};
  }
  std::string held;
  for (uint8_t id : targets) {
    ServoStatus status = refuseWhileLocked(id);
    if (!status.ok()) return status;
    double angle_deg = 0.0;
    status = client_.readAngle(id, &angle_deg);
    if (!status.ok()) return status;
    RotateRequest request;
    request.id = id;
    request.angle_deg = angle_deg;
    status = client_.rotate(request);
    if (!status.ok()) return status;
    noteMotion(id, false);  // holding where it is: not set moving
    char text[48];
    std::snprintf(text, sizeof(text), "%s%u at %.1f deg", held.empty() ? "" : ", ", id, angle_deg);
    held += text;
  }
  return {ServoError::kOk, "holding servo(s) " + held};
}

bool ServoBus::motionLocked() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return motion_locked_;
}

std::vector<uint8_t> ServoBus::movingIds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {moving_.begin(), moving_.end()};
}

std::vector<uint8_t> ServoBus::commandedIds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {commanded_.begin(), commanded_.end()};
}

}  // namespace serial_robot_driver::device
