// The base's turning calibration (calibrate_base): how far the robot really turned, from the IMU's
// gyro, against how far its wheels were commanded to turn, from the wheel frames actually written.
// A slippery floor or worn tyres make the real turn smaller than the commanded one; the fix is an
// effective wheel separation (configured × commanded / measured), like diff_drive_controller's
// wheel-separation multiplier. The straight-line check does the same for the wheel diameter
// against a distance the user measures.
//
// ROS-free: calibrate_base's run (turn_calibration_run.h) feeds it stamps in seconds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "serial_robot_driver/kinematics/diff_drive.h"

namespace serial_robot_driver::devices::base {

/// One turn (or straight run) as recorded: both integrals over the same window, which starts and
/// ends with the base at rest, so the IMU's lag behind the wheel frames does not matter.
struct MotionRecord {
  double commanded_yaw = 0;       ///< rad, from the wheel frames written (counter-clockwise > 0)
  double commanded_distance = 0;  ///< m, the wheels' mean travel from the same frames
  double measured_yaw = 0;        ///< rad, the IMU's yaw rate integrated
  double imu_duration = 0;        ///< s between the first and the last IMU sample
  double longest_imu_gap = 0;     ///< s, the longest silence between two IMU samples
  std::size_t imu_samples = 0;
  std::size_t wheel_frames = 0;
};

/// Integrates wheel frames and IMU yaw rates into a MotionRecord.
class MotionRecorder {
 public:
  /// `geometry` converts ticks per PID period into wheel speeds and `left_direction`,
  /// `right_direction` (1 or -1) wire ticks into robot-side ones: the node's configured values.
  /// A frame's speeds hold until the next frame, at most `max_frame_hold_s` (the AP1 stops by
  /// itself after its 1 s heartbeat timeout).
  explicit MotionRecorder(const kinematics::DiffDriveGeometry& geometry, int left_direction = 1,
                          int right_direction = 1, double max_frame_hold_s = 1.0);

  /// A wheel frame with these ticks per PID period, as on the wire (wheel directions applied, as
  /// wheel_command carries them), was written at `stamp` (s).
  void addWheelFrame(double stamp, int16_t left_ticks, int16_t right_ticks);
  /// The IMU measured `yaw_rate` (rad/s, counter-clockwise > 0) at `stamp` (s).
  void addImuRate(double stamp, double yaw_rate);
  /// The commanded yaw so far, the last frame held until `now` (s): how far the turn has come.
  double commandedYawUntil(double now) const;
  /// The record with the last frame held until `end` (s), the end of the window.
  MotionRecord finish(double end) const;

 private:
  double heldFor(double from, double to) const;

  kinematics::DiffDriveGeometry geometry_;
  int left_direction_;
  int right_direction_;
  double max_frame_hold_s_;
  MotionRecord record_;
  std::optional<double> last_frame_stamp_;
  double last_turn_rate_ = 0;      ///< rad/s of the last frame
  double last_forward_speed_ = 0;  ///< m/s of the last frame
  std::optional<double> last_imu_stamp_;
  std::optional<double> first_imu_stamp_;
  double last_yaw_rate_ = 0;
};

/// What makes a result absurd: refused rather than reported.
struct CalibrationLimits {
  double min_ratio = 0.5;  ///< measured / commanded
  double max_ratio = 1.5;
  std::size_t min_imu_samples = 20;          ///< per turn
  double max_imu_gap = 0.5;                  ///< s without an IMU sample inside a turn
  double min_commanded_turn = 0.5;           ///< rad per turn
  double max_direction_disagreement = 0.15;  ///< |ratio ccw - ratio cw|
  double min_commanded_distance = 0.1;       ///< m
};

struct TurnCalibration {
  double ratio = 0;      ///< measured / commanded turn, the gyro's constant bias removed
  double ratio_ccw = 0;  ///< each direction alone (bias included)
  double ratio_cw = 0;
  double gyro_bias = 0;             ///< rad/s, the constant bias both turns together reveal
  double effective_separation = 0;  ///< m
};

struct DiameterCalibration {
  double ratio = 0;               ///< measured / commanded distance
  double effective_diameter = 0;  ///< m
};

/// Either a value or the reason it was refused.
template <typename T>
struct Checked {
  std::optional<T> value;
  std::string error;  ///< empty when value is set
};

/// Combines a counter-clockwise and a clockwise turn. With a constant gyro bias b each turn
/// measures k·commanded + b·duration; the two turns give k and b exactly (opposite commanded
/// signs), so the bias cancels even when the turns took different times.
/// `configured_separation` in m; `diameter_scale` = effective / configured wheel diameter when the
/// diameter is corrected too (the wheels then travel that much more, so does the commanded turn).
Checked<TurnCalibration> calibrateTurn(const MotionRecord& ccw, const MotionRecord& cw,
                                       double configured_separation, double diameter_scale = 1.0,
                                       const CalibrationLimits& limits = {});

/// The straight-line check: the commanded distance against the one the user measured (m).
Checked<DiameterCalibration> calibrateDiameter(const MotionRecord& straight,
                                               double measured_distance, double configured_diameter,
                                               const CalibrationLimits& limits = {});

}  // namespace serial_robot_driver::devices::base
