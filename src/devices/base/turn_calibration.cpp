#include "serial_robot_driver/devices/base/turn_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

namespace serial_robot_driver::devices::base {

namespace {

std::string format(const char* pattern, double a, double b = 0, double c = 0) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, a, b, c);
  return text;
}

/// Why one turn cannot be used, "" when it can. `sign` is +1 for the counter-clockwise turn.
std::string checkTurn(const MotionRecord& turn, const char* name, double sign,
                      const CalibrationLimits& limits) {
  if (turn.imu_samples < limits.min_imu_samples) {
    return std::string("too few IMU samples in the ") + name +
           " turn: " + std::to_string(turn.imu_samples) + " (at least " +
           std::to_string(limits.min_imu_samples) + "; is telemetry streaming?)";
  }
  if (turn.longest_imu_gap > limits.max_imu_gap) {
    return std::string("telemetry stopped during the ") + name + " turn" +
           format(" (%.2f s without an IMU sample)", turn.longest_imu_gap);
  }
  if (turn.commanded_yaw * sign < limits.min_commanded_turn) {
    return std::string("the base was hardly commanded to turn ") + name +
           format(" (%.3f rad from the wheel frames written; e-stop or zero speed limit?)",
                  turn.commanded_yaw);
  }
  return "";
}

}  // namespace

MotionRecorder::MotionRecorder(const kinematics::DiffDriveGeometry& geometry, int left_direction,
                               int right_direction, double max_frame_hold_s)
    : geometry_(geometry),
      left_direction_(left_direction),
      right_direction_(right_direction),
      max_frame_hold_s_(max_frame_hold_s) {}

double MotionRecorder::heldFor(double from, double to) const {
  return std::clamp(to - from, 0.0, max_frame_hold_s_);
}

void MotionRecorder::addWheelFrame(double stamp, int16_t left_ticks, int16_t right_ticks) {
  if (last_frame_stamp_) {
    const double held = heldFor(*last_frame_stamp_, stamp);
    record_.commanded_yaw += last_turn_rate_ * held;
    record_.commanded_distance += last_forward_speed_ * held;
  }
  // Ticks per PID period -> m/s: the base runs pid_rate periods a second.
  const double mps_per_tick = geometry_.pid_rate / geometry_.ticksPerMeter();
  // A direction of -1 negates a wheel's ticks on the wire; negating again gives the robot's.
  const double left = left_ticks * left_direction_ * mps_per_tick;
  const double right = right_ticks * right_direction_ * mps_per_tick;
  last_turn_rate_ = (right - left) / geometry_.wheel_separation;
  last_forward_speed_ = (left + right) / 2.0;
  last_frame_stamp_ = stamp;
  ++record_.wheel_frames;
}

void MotionRecorder::addImuRate(double stamp, double yaw_rate) {
  if (last_imu_stamp_) {
    const double gap = stamp - *last_imu_stamp_;
    record_.longest_imu_gap = std::max(record_.longest_imu_gap, gap);
    // Trapezoids: the rate changes linearly between samples while the base speeds up or slows.
    record_.measured_yaw += (yaw_rate + last_yaw_rate_) / 2.0 * gap;
  } else {
    first_imu_stamp_ = stamp;
  }
  last_imu_stamp_ = stamp;
  last_yaw_rate_ = yaw_rate;
  record_.imu_duration = stamp - *first_imu_stamp_;
  ++record_.imu_samples;
}

double MotionRecorder::commandedYawUntil(double now) const {
  if (!last_frame_stamp_) return record_.commanded_yaw;
  return record_.commanded_yaw + last_turn_rate_ * heldFor(*last_frame_stamp_, now);
}

MotionRecord MotionRecorder::finish(double end) const {
  MotionRecord record = record_;
  if (last_frame_stamp_) {
    const double held = heldFor(*last_frame_stamp_, end);
    record.commanded_yaw += last_turn_rate_ * held;
    record.commanded_distance += last_forward_speed_ * held;
  }
  return record;
}

Checked<TurnCalibration> calibrateTurn(const MotionRecord& ccw, const MotionRecord& cw,
                                       double configured_separation, double diameter_scale,
                                       const CalibrationLimits& limits) {
  for (const auto& [turn, name, sign] :
       {std::tuple{&ccw, "counter-clockwise", 1.0}, std::tuple{&cw, "clockwise", -1.0}}) {
    std::string why = checkTurn(*turn, name, sign, limits);
    if (!why.empty()) return {std::nullopt, why};
  }
  TurnCalibration result;
  result.ratio_ccw = ccw.measured_yaw / ccw.commanded_yaw;
  result.ratio_cw = cw.measured_yaw / cw.commanded_yaw;
  if (result.ratio_ccw <= 0 || result.ratio_cw <= 0) {
    return {std::nullopt,
            format("the IMU measured a turn of the opposite sign (measured/commanded %.3f "
                   "counter-clockwise, %.3f clockwise): is the board mounted upside down, or "
                   "the wheels swapped?",
                   result.ratio_ccw, result.ratio_cw)};
  }
  // measured = ratio * commanded + bias * duration, once per direction: two equations, two
  // unknowns. The commanded turns have opposite signs, so the determinant is never zero.
  const double determinant =
      ccw.commanded_yaw * cw.imu_duration - cw.commanded_yaw * ccw.imu_duration;
  result.ratio =
      (ccw.measured_yaw * cw.imu_duration - cw.measured_yaw * ccw.imu_duration) / determinant;
  result.gyro_bias =
      (ccw.commanded_yaw * cw.measured_yaw - cw.commanded_yaw * ccw.measured_yaw) / determinant;
  if (std::abs(result.ratio_ccw - result.ratio_cw) > limits.max_direction_disagreement) {
    return {std::nullopt,
            format("the two directions disagree: measured/commanded %.3f counter-clockwise, "
                   "%.3f clockwise (a large gyro bias: call imu/calibrate first; or an uneven "
                   "floor)",
                   result.ratio_ccw, result.ratio_cw)};
  }
  if (result.ratio < limits.min_ratio || result.ratio > limits.max_ratio) {
    return {std::nullopt,
            format("measured/commanded turn %.3f is outside %.2f..%.2f: not a matter of wheel "
                   "separation (check the IMU's gyro_scale and the configured geometry)",
                   result.ratio, limits.min_ratio, limits.max_ratio)};
  }
  result.effective_separation = configured_separation * diameter_scale / result.ratio;
  return {result, ""};
}

Checked<DiameterCalibration> calibrateDiameter(const MotionRecord& straight,
                                               double measured_distance, double configured_diameter,
                                               const CalibrationLimits& limits) {
  if (straight.commanded_distance < limits.min_commanded_distance) {
    return {std::nullopt, format("the base was hardly commanded forward (%.3f m from the wheel "
                                 "frames written; at least %.2f m)",
                                 straight.commanded_distance, limits.min_commanded_distance)};
  }
  DiameterCalibration result;
  result.ratio = measured_distance / straight.commanded_distance;
  if (!(result.ratio >= limits.min_ratio && result.ratio <= limits.max_ratio)) {
    return {std::nullopt,
            format("measured %.3f m for %.3f m commanded: a ratio outside %.2f", measured_distance,
                   straight.commanded_distance, limits.min_ratio) +
                format("..%.2f is a measuring mistake, not the wheels", limits.max_ratio)};
  }
  result.effective_diameter = configured_diameter * result.ratio;
  return {result, ""};
}

}  // namespace serial_robot_driver::devices::base
