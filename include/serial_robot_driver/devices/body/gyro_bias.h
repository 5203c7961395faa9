// The board's gyro bias, ROS-free: averaging the gyro while the robot is held still (imu/calibrate,
// ~imu/calibrate_on_start), deciding whether the mean is a believable bias, and keeping the bias in
// force for the conversion to subtract.
//
// The bias is kept in the gyro's raw units (LSB) on the sensor's own axes, so a runtime change of
// ~imu/gyro_scale or the axis map applies to it exactly as to the raw samples it came from.
//
// Threading: onSample() runs on the body port's reader thread; calibrate() blocks its caller (a
// service thread) for the averaging time; bias(), report() and cancel() may be called from any
// thread. One mutex guards everything; the stillness check is always called without it held, so
// it may take another device's lock.
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/devices/body/body_params.h"

namespace serial_robot_driver::devices::body {

/// One value per sensor axis (x, y, z).
using GyroVector = std::array<double, 3>;

/// How raw gyro values read in rad/s on imu/data's axes (~imu/gyro_scale and ~imu/axis_map).
struct GyroUnits {
  double gyro_scale = 0.0010653;  ///< rad/s per LSB
  AxisMap axes;
  /// `raw` (LSB, sensor axes) in rad/s on the imu frame's axes.
  GyroVector toImuRadPerSecond(const GyroVector& raw) const;
};

/// How long the robot must have been seen still (nothing the node drives commanded to move, the
/// e-stop released) before the gyro is averaged: a turn, a joint or a servo takes a moment to come
/// to rest after its command ends, and a slow, smooth rotation would be stored as the bias.
constexpr std::chrono::milliseconds kGyroSettleTime{1000};

struct GyroCalibrationLimits {
  /// A mean above this on any axis (rad/s) is a turn, not a bias (gyro biases are a few mrad/s).
  double max_bias = 0.1;
  /// A standard deviation above this on any axis (rad/s) means the robot was shaken or bumped: a
  /// still board's noise is far smaller.
  double max_spread = 0.05;
  std::size_t min_samples = 10;
  /// The newest IMU frame must be younger than this for telemetry to count as flowing.
  std::chrono::milliseconds max_telemetry_age{500};
  /// Still for this long before the averaging starts.
  std::chrono::milliseconds settle = kGyroSettleTime;
  /// While no calibration averages or waits to start, a frame asks whether anything moves only
  /// when the last frame that asked is this much older; the frames between keep its answer. The
  /// question takes every device's lock, and every motion lasts far longer than this (a joint
  /// command counts for 0.5 s, a cmd_vel until it times out, a servo until it is stopped), so
  /// the settle time only counts from a look up to this much after the motion ended. 0: every
  /// frame asks.
  std::chrono::milliseconds idle_motion_look{50};
};

/// Mean and spread per axis of raw gyro samples (Welford's running update: no catastrophic
/// cancellation however many samples).
class GyroSampleStats {
 public:
  void add(const GyroVector& raw);
  std::size_t count() const { return count_; }
  GyroVector mean() const { return mean_; }
  /// Sample standard deviation per axis (0 with fewer than two samples).
  GyroVector spread() const;

 private:
  std::size_t count_ = 0;
  GyroVector mean_{};
  GyroVector squares_{};  ///< sum of squared differences from the mean
};

/// The verdict on a set of samples: the bias (LSB, sensor axes) or why it is not one.
struct GyroBiasDecision {
  std::optional<GyroVector> bias;
  std::string problem;  ///< empty when bias is set
};
GyroBiasDecision decideGyroBias(const GyroSampleStats& stats, const GyroUnits& units,
                                const GyroCalibrationLimits& limits);

/// "(0.02, -0.015, 0.03) rad/s = (1.15, -0.86, 1.72) deg/s" for `raw` on the imu frame's axes.
std::string describeGyroBias(const GyroVector& raw, const GyroUnits& units);

/// The result of one calibration, as the service answers it.
struct GyroCalibrationOutcome {
  bool success = false;
  std::string message;
  /// Refused because the robot was not held still (moving, ramping, e-stop): worth trying again
  /// once it is.
  bool not_still = false;
};

class GyroBiasCalibrator {
 public:
  /// Why the robot is not held still now (a motion command in force, wheels ramping, the e-stop
  /// engaged), or "" when it is. Thread-safe and cheap: it is asked once per IMU frame (the
  /// settle time counts from the first frame it answers "" after a motion).
  using StillnessCheck = std::function<std::string()>;
  /// Whether anything may be moving the robot now: what StillnessCheck answers, as a bool that
  /// builds no text. Thread-safe.
  using MotionCheck = std::function<bool()>;
  /// calibrate_on_start's verdict, called once on the reader thread (log it).
  using StartReport = std::function<void(const GyroCalibrationOutcome&)>;

  /// With `moving`, each frame asks only it, and `still` only for the text where it is kept: the
  /// frame a motion starts on, and while a calibration averages. Without it, `still` every frame.
  explicit GyroBiasCalibrator(StillnessCheck still, GyroCalibrationLimits limits = {},
                              MotionCheck moving = {});

  /// Reader thread: one frame's raw gyro (LSB, sensor axes) arrived at `arrival`. `units` and
  /// `seconds` (~imu/calibration_time) are the ones in force for this frame. Returns the bias in
  /// force after it (bias()): one that this frame completed is new. The body asks bias() before
  /// it publishes a frame and hands the frame here after, so a new bias applies from the next one.
  GyroVector onSample(const GyroVector& raw, core::Clock::time_point arrival,
                      const GyroUnits& units, double seconds);
  /// Blocks the caller for `seconds` while the samples arrive, then keeps the bias found or
  /// nothing (a refusal changes nothing in force). Refused unless the robot has been seen still
  /// for the settle time (limits). `how` names the request ("imu/calibrate").
  GyroCalibrationOutcome calibrate(double seconds, const GyroUnits& units, const std::string& how);
  /// Arms ~imu/calibrate_on_start: the first frames that arrive while the robot is still are
  /// averaged for `seconds` (onSample's), the result or refusal reported once through `report`; a
  /// motion during the averaging only starts it again once the robot is still.
  void calibrateOnStart(StartReport report);
  /// Shutdown: a calibration under way is refused at once, and so is every later one.
  void cancel();

  /// The bias in force (LSB, sensor axes; zero when never calibrated).
  GyroVector bias() const;
  /// The bias in force and the last calibration's verdict, added to the body's status: a refusal
  /// since the last good calibration is a WARN.
  void report(core::StatusReport& status, const GyroUnits& units) const;

 private:
  struct InForce {
    GyroVector bias{};
    std::size_t samples = 0;
    double seconds = 0;
    std::string how;
    std::chrono::system_clock::time_point when;
  };
  struct Session {
    std::string how;
    core::Clock::time_point begin;
    core::Clock::time_point end;
    double seconds = 0;
    GyroSampleStats stats;
    std::string not_still;  ///< set when the robot moved during the averaging
    bool automatic = false;
  };

  /// Requires mutex_: the outcome of `session` (over), applied when it is a bias.
  GyroCalibrationOutcome finishLocked(const Session& session, const GyroUnits& units);
  std::string inForceLocked(const GyroUnits& units) const;
  /// Whether the robot has been seen still for the settle time at `now`.
  bool settledLocked(core::Clock::time_point now) const;
  /// Why it has not (settledLocked() false).
  std::string unsettledLocked(core::Clock::time_point now) const;
  GyroCalibrationOutcome refuseLocked(const std::string& how, const std::string& why,
                                      const GyroUnits& units, bool not_still);
  /// Without mutex_: nullopt while nothing moves; else what moves, "" when `name_it` is false.
  std::optional<std::string> motionNow(bool name_it) const;
  /// Requires mutex_: whether the frame at `arrival` asks motionNow() or keeps the last answer.
  bool looksForMotionLocked(core::Clock::time_point arrival, bool after_gap) const;
  /// Requires mutex_: a frame at `arrival` found `motion` (motionNow()).
  void noteMotionLocked(const std::optional<std::string>& motion, core::Clock::time_point arrival,
                        bool after_gap);

  const StillnessCheck still_;
  const MotionCheck moving_;
  const GyroCalibrationLimits limits_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<InForce> in_force_;
  std::optional<Session> session_;
  std::optional<core::Clock::time_point> last_arrival_;
  /// Since when every frame found the robot still (the end of the last motion, or the first frame
  /// after a telemetry gap: what happened in the gap is unknown); unset while it moves.
  std::optional<core::Clock::time_point> still_since_;
  /// The arrival of the last frame that asked whether anything moves, and what it found.
  std::optional<core::Clock::time_point> last_look_;
  bool last_look_moved_ = false;
  std::string last_motion_;   ///< what the last motion began with (still_since_ its end)
  std::string last_refusal_;  ///< since the last good calibration
  StartReport start_report_;  ///< set while calibrate_on_start waits for its result
  bool cancelled_ = false;
};

}  // namespace serial_robot_driver::devices::body
