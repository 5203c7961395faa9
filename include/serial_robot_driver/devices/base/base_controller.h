// The AP1 wheeled base as the driver sees it: cmd_vel in, wheel-speed frames out at the loop rate,
// the 1 s heartbeat, the Reset/timeout-error cycle, battery polling and encoder clearing.
// ROS-free: the ROS layer feeds commands in and publishes the events it reports.
//
// Threading model:
//  - start() runs the control loop on its own thread (SCHED_FIFO with config.realtime_priority,
//    where the process may): absolute deadlines on the LoopClock (the
//    steady clock unless a test passes its own) (deadline += period, never "sleep one period"), so
//    the period does not drift. Each tick writes
//    the current wheel frame, which is also the heartbeat.
//  - submitCommand() (the cmd_vel callback's thread) writes the command's wheel frame itself, at
//    once, under mutex_: what goes out (e-stop, deadman, limits, ramp, SEQ) is decided at the
//    moment of writing, exactly as a tick decides it, and the next tick goes on from that frame.
//    Such immediate frames are spaced from each other by what the line can carry
//    (minImmediateInterval()), never by the loop rate or the last tick, and never move the tick
//    deadlines; a command that comes sooner (a flood), or before start(), is stored and the loop
//    writes it when the line allows. setEStop() stores and wakes the loop, which writes the zero
//    frame at once.
//  - onFrame() runs on the port's reader thread: an FF error frame wakes the loop to send a Reset.
//  - Every base write happens with mutex_ held, so the sequence counter and "Reset before the next
//    speed frame" are consistent whichever thread writes (loop, or a base/* service).
//  - The BaseEvents hooks are called without mutex_ held, on the thread that caused them (loop,
//    reader, or the caller of stop()); on_wheel_frame in the order the frames were written (the
//    loop and a cmd_vel's caller may both write: report_mutex_ keeps one reporter at a time).
//    Stats are one struct under mutex_; stats() is a snapshot.
//  - Odometry (mutex_) integrates the wheel speeds of each speed frame the base accepted, from its
//    write until the next accepted frame, the base's own 1 s timeout, or an FF error, whichever
//    comes first. The loop reports a sample after every scheduled tick (on_odometry).
//  - With use_imu_heading, onImuYaw() runs on the body port's reader thread and only hands the
//    sample to kinematics::HeadingFusion (its own short lock, never mutex_, so telemetry never
//    waits for a base write); the loop reads the newest sample when it advances the odometry.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/loop_clock.h"
#include "serial_robot_driver/core/loop_wake.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/base/base_odometry.h"
#include "serial_robot_driver/kinematics/diff_drive.h"
#include "serial_robot_driver/kinematics/heading_fusion.h"
#include "serial_robot_driver/kinematics/odometry.h"

namespace serial_robot_driver::devices::base {

/// The part of the configuration that can change while the loop runs (retune() takes it over
/// whole). Each tunable parameter's row binds straight to its field here.
struct BaseTuning {
  /// Only wheel_diameter and wheel_separation are offered for runtime tuning (encoder_resolution
  /// and pid_rate are the base's firmware), but the controller follows any geometry it is given.
  kinematics::DiffDriveGeometry geometry;
  double max_wheel_speed = 1.0;  ///< m/s; must be > 0 (no "no limit" value)
  double max_wheel_accel = 0.0;  ///< m/s^2; 0: no limit
  double cmd_vel_timeout = 0.5;  ///< s without a command: zero speed; > 0, <= the maximum
  /// The longest cmd_vel_timeout (s): the deadman that stops the base when its client dies
  /// (calibrate_base killed hard included) cannot be tuned away.
  static constexpr double kMaxCmdVelTimeout = 5.0;
  bool speed_dithering = true;     ///< carry the tick remainder (false: vendor truncation)
  double battery_poll_rate = 1.0;  ///< Hz; 0: never ask
  /// Odometry's heading from the IMU yaw given to onImuYaw() while it is fresh (see
  /// kinematics::HeadingFusion); the commanded turn otherwise.
  bool use_imu_heading = false;
};

struct BaseConfig : BaseTuning {
  double loop_rate = 50.0;     ///< Hz
  double heartbeat_gap = 1.0;  ///< s; a gap this long in our sending means the base timed out
  int baud = 115200;           ///< of the base's port: sets how closely immediate frames follow
  /// Largest share of the line's capacity immediate speed frames may take (a cmd_vel flood).
  double immediate_line_share = 0.5;
  int left_wheel_direction = 1;  ///< 1 or -1: sign between forward motion and the wire's ticks
  int right_wheel_direction = 1;
  /// With battery polling on, this many poll periods without any reply mean the base is silent.
  double silent_after_polls = 3.0;
  kinematics::PoseCovarianceModel odometry_covariance;
  /// rad^2, odom's yaw variance while the IMU heading is used (until setImuYawVariance()).
  double imu_yaw_variance = 0.0003;
  core::Clock::duration imu_stale_after = kinematics::kImuHeadingStaleAfter;
  /// The loop thread's SCHED_FIFO priority (core/realtime.h: ~realtime_priority); 0: normal.
  int realtime_priority = 0;
  /// The loop thread's fair-scheduler slice (core/scheduler_slice.h); 0: the kernel's.
  int scheduler_slice_us = 0;
};

/// Where the odometry stood after a scheduled tick.
struct OdometrySample {
  core::Clock::time_point time;
  kinematics::Pose2D pose;
  double linear = 0;             ///< m/s the base runs at now (0 once its timeout stopped it)
  double angular = 0;            ///< rad/s
  double position_variance = 0;  ///< m^2, x and y
  double yaw_variance = 0;       ///< rad^2
  double travelled = 0;          ///< m since the last reset
  /// Each wheel's signed path (left, right; m) since the controller started, from the same
  /// accepted speeds as the pose; reset_odometry leaves it alone (wheel angles do not jump).
  kinematics::WheelSpeeds wheel_travel = kinematics::WheelSpeeds::Zero();
  /// Each wheel's speed (left, right; m/s) the base runs at now (0 once its timeout stopped it).
  kinematics::WheelSpeeds wheel_speeds = kinematics::WheelSpeeds::Zero();
  /// Each wheel's angle (left, right; rad): wheel_travel through the wheel radius, continuous
  /// when the diameter is retuned (the travel before a change keeps the radius it had).
  kinematics::WheelSpeeds wheel_angles = kinematics::WheelSpeeds::Zero();
  /// wheel_speeds as the wheels' angular speeds (rad/s) with the diameter in force.
  kinematics::WheelSpeeds wheel_rates = kinematics::WheelSpeeds::Zero();
  /// Where the heading came from (kImu only with use_imu_heading).
  bool imu_heading = false;
};

/// One wheel frame as written.
struct WheelFrameSent {
  kinematics::WheelTicks ticks;  ///< as on the wire (wheel directions applied)
  uint8_t seq = 0;
  bool reset_before = false;
  kinematics::WheelSpeeds speeds = kinematics::WheelSpeeds::Zero();  ///< m/s the ticks stand for
  core::Clock::time_point time;
};

struct BaseStats {
  uint64_t speed_frames = 0;
  uint64_t immediate_frames = 0;  ///< speed frames sent at once for a new cmd_vel
  uint64_t resets_sent = 0;
  uint64_t battery_requests = 0;
  uint64_t clear_encoders_sent = 0;
  uint64_t write_failures = 0;
  uint64_t timeout_errors_received = 0;  ///< FF frames from the base
  uint64_t battery_replies = 0;
  uint64_t unknown_replies = 0;
  uint64_t bad_replies = 0;
  uint64_t cmd_vel_timeouts = 0;
  uint64_t rejected_commands = 0;        ///< NaN/Inf cmd_vel
  uint64_t ignored_commands_e_stop = 0;  ///< cmd_vel received while the e-stop was engaged
  /// cmd_vel accepted before an e-stop that engaged before it was stored (even one released since)
  uint64_t voided_commands = 0;
  uint64_t timeout_errors_while_running = 0;  ///< FF after the base had accepted our Reset
  std::optional<double> seconds_since_running_timeout_error;
  /// Battery polling on and requests unanswered: seconds since the first unanswered request.
  std::optional<double> seconds_without_reply;
  bool base_silent = false;  ///< seconds_without_reply beyond BaseConfig::silent_after_polls
  bool e_stop = false;
  double min_immediate_interval_ms = 0;
  uint64_t loop_overruns = 0;  ///< ticks that started more than one period late
  /// Exceptions a tick (or a rushed frame) let out of the loop: caught, that step cut short, and
  /// the loop goes on. The last one's text.
  uint64_t internal_errors = 0;
  std::string last_internal_error;
  double last_period_ms = 0;
  double worst_period_ms = 0;
  std::optional<uint8_t> battery_percent;
  /// use_imu_heading only: where the heading comes from, how often the IMU went stale, and the
  /// age of the newest IMU yaw (s).
  std::optional<kinematics::HeadingSource> heading_source;
  uint64_t imu_heading_fallbacks = 0;
  std::optional<double> imu_yaw_age;
};

/// What the base reports; every hook may be empty. Called without the controller's lock held.
struct BaseEvents {
  std::function<void(const WheelFrameSent&)> on_wheel_frame;
  /// `arrival`: when the reply's last byte was read (its stamp).
  std::function<void(uint8_t percent, core::Clock::time_point arrival)> on_battery;
  std::function<void(const Frame&)> on_unknown_reply;
  std::function<void()> on_timeout_error;
  std::function<void(const OdometrySample&)> on_odometry;  ///< after every scheduled tick
  std::function<void()> on_cmd_vel_timeout;                ///< once per timeout, when it starts
  std::function<void(double seconds)> on_silent;           ///< once, when the base goes silent
  /// use_imu_heading: the heading's source changed (IMU fused, or the IMU went stale); loop thread.
  std::function<void(kinematics::HeadingSource)> on_heading_source;
};

/// What became of a cmd_vel (submitCommand()).
enum class CommandOutcome {
  kSent,          ///< obeyed: its frame was written at once, on the caller's thread
  kStored,        ///< obeyed from the next frame on (the loop writes it when the line allows)
  kNotFinite,     ///< NaN/Inf: zero speed commanded instead
  kEStopEngaged,  ///< ignored: the e-stop is engaged
  kVoided,        ///< ignored: an e-stop engaged after it was accepted (even if released since)
};

class BaseController : public core::LinkListener {
 public:
  /// Counts the e-stop's engagements: a cmd_vel accepted under one never drives under a later one.
  using Generation = uint64_t;

  /// `clock` empty: the steady clock.
  BaseController(BaseConfig config, core::FrameWriter writer, BaseEvents events = {},
                 std::shared_ptr<core::LoopClock> clock = {});
  ~BaseController() override;

  /// Obeys a cmd_vel: its wheel frame is written before this returns (kSent) while the loop runs
  /// and the line has room for it; otherwise the loop writes it as soon as it may (kStored).
  /// NaN/Inf components are rejected: zero speed is commanded (by the loop). Ignored (and counted)
  /// while the e-stop is engaged, and when `accepted` (generation() when the command was accepted,
  /// noted before its e-stop check) is older than the last engagement: then nothing is written.
  CommandOutcome submitCommand(double linear_x, double angular_z,
                               std::optional<Generation> accepted = std::nullopt);
  /// submitCommand() accepted now; false for NaN/Inf components.
  bool setCommand(double linear_x, double angular_z) {
    return submitCommand(linear_x, angular_z) != CommandOutcome::kNotFinite;
  }
  /// The e-stop generation a cmd_vel accepted now belongs to.
  Generation generation() const;
  /// Engaged: the command in force is dropped, a zero-speed frame goes out at once (no ramp) and
  /// zero is held; frames keep flowing. Released: the wheels stay still until a cmd_vel accepted
  /// after the release.
  void setEStop(bool engaged);
  /// Puts the odometry pose (and its covariance) back to zero; a fused heading restarts at zero
  /// too.
  void resetOdometry();
  /// Any thread (the body port's reader): the yaw (rad) of the IMU on the base, measured at
  /// `stamp`. Used only with use_imu_heading.
  void onImuYaw(double yaw, core::Clock::time_point stamp);
  /// The variance (rad^2) of the yaws given to onImuYaw() (what the measuring sensor says of
  /// them): odom's yaw variance while the IMU heading is used. Before start().
  void setImuYawVariance(double variance);
  /// The shortest spacing of speed frames sent at once for a new command: the frame's airtime at
  /// the port's baud (10 bits per byte) divided by immediate_line_share.
  core::Clock::duration minImmediateInterval() const { return min_immediate_interval_; }
  /// Why the wheels may be moving now, or "" when they are commanded still: a non-zero cmd_vel in
  /// force (not timed out, no e-stop) or wheels still ramping toward zero. Any thread.
  std::string motionInForce() const;
  /// Whether motionInForce() would name something, without building its text. Any thread.
  bool inMotion() const;
  /// Writes a Reset now (base/reset). False when the port is down.
  bool sendReset();
  /// Writes a clear-encoders frame now (base/clear_encoders). False when the port is down.
  bool sendClearEncoders();

  /// Takes over `next` (a whole BaseConfig passes its BaseTuning part) from the next frame on,
  /// all at once (under the loop's lock), and recomputes what derives from it: the acceleration
  /// limiter, the tick quantizer, the odometry's geometry and heading source, the battery poll
  /// schedule. The rest of the configuration needs a new controller. No Reset, the sequence goes
  /// on, the odometry keeps its pose: the motion up to now is integrated with the geometry it ran
  /// under, from now on with the new one. Expects validated values.
  void retune(const BaseTuning& next);
  /// The configuration in force.
  BaseConfig config() const;

  void start();
  /// Stops the loop and writes one zero-speed frame, so the robot stops before the port closes.
  void stop();

  BaseStats stats() const;

  // LinkListener (reader thread)
  void onLinkUp() override;
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               core::Clock::time_point arrival) override;

 private:
  void run();
  /// Runs one step of the loop (a tick, a rushed frame) guarded: see BaseStats::internal_errors.
  template <typename Step>
  void guarded(const Step& step);
  /// A scheduled tick: battery poll when due, then the wheel frame.
  void tick(core::Clock::time_point now);
  /// What a written wheel frame reports once mutex_ is released.
  struct SpeedFrameReport {
    std::optional<WheelFrameSent> sent;  ///< set when the speed frame was written
    bool timed_out_now = false;          ///< the cmd_vel timeout started with it
  };
  /// Sends the wheel frame for the current command (Reset first when needed).
  void sendSpeed(core::Clock::time_point now, bool immediate);
  /// Requires mutex_: sendSpeed()'s decision and writes, its report in `report`.
  void sendSpeedLocked(core::Clock::time_point now, bool immediate, SpeedFrameReport* report);
  /// Without mutex_: the events of a frame sendSpeedLocked() wrote.
  void reportSpeedFrame(const SpeedFrameReport& report);
  /// Without mutex_: on_wheel_frame for every written frame not reported yet, in write order.
  void reportWrittenFrames();
  /// Requires mutex_: whether a cmd_vel may be written by its caller now (the loop runs, and the
  /// last immediate frame is minImmediateInterval() ago).
  bool mayRushLocked(core::Clock::time_point now) const;
  bool lineAllowsImmediateLocked(core::Clock::time_point now) const;
  /// Requires mutex_: a non-zero cmd_vel in force (not timed out, no e-stop).
  bool commandMovesLocked(core::Clock::time_point now) const;
  /// Requires mutex_: the wheels still ramping toward zero (no e-stop).
  bool rampingLocked() const;
  /// Requires mutex_. Writes one frame with the next SEQ; false on failure.
  bool writeLocked(const std::vector<uint8_t>& frame, core::Clock::time_point now);
  /// `timed_out_now`: set when the cmd_vel timeout started with this call.
  kinematics::WheelSpeeds targetSpeedsLocked(core::Clock::time_point now, bool* timed_out_now);
  kinematics::WheelTicks onWire(const kinematics::WheelTicks& ticks) const;
  /// Requires mutex_, before the rate in force changes: the next poll for `next_rate`.
  void rescheduleBatteryPollLocked(double next_rate, core::Clock::time_point now);

  BaseConfig config_;  ///< its BaseTuning part changes under mutex_ (retune)
  const core::FrameWriter writer_;
  const BaseEvents events_;
  const std::shared_ptr<core::LoopClock> clock_;
  const core::Clock::duration period_;
  const core::Clock::duration min_immediate_interval_;

  mutable std::mutex mutex_;
  /// Taken before mutex_, never while holding it.
  std::mutex report_mutex_;
  /// Under mutex_: frames written, not yet reported.
  std::deque<WheelFrameSent> unreported_frames_;
  /// Ends the loop's wait for a command, an e-stop, an FF error, a link up or stop(); the state
  /// it is for is set under mutex_ first.
  core::LoopWake wake_;
  bool stopping_ = false;
  bool stopped_ = false;
  bool running_ = false;          ///< between start() and stop(): cmd_vel written by its caller
  bool command_pending_ = false;  ///< a new cmd_vel or an FF error wants an early frame
  SequenceCounter seq_;
  kinematics::AccelerationLimiter limiter_;
  kinematics::TickQuantizer quantizer_;
  double linear_x_ = 0;
  double angular_z_ = 0;
  std::optional<core::Clock::time_point> last_command_;
  bool command_timed_out_ = true;
  bool needs_reset_ = true;
  std::optional<core::Clock::time_point> last_write_;  ///< any base frame
  std::optional<core::Clock::time_point> last_speed_frame_;
  std::optional<core::Clock::time_point>
      last_immediate_frame_;  ///< the last one a command rushed out
  std::optional<core::Clock::time_point> last_tick_;
  core::Clock::time_point next_battery_poll_{};
  bool e_stop_ = false;
  Generation generation_ = 0;  ///< e-stop engagements so far
  BaseOdometry odometry_;      ///< not thread-safe: used under mutex_ (onImuYaw excepted)
  std::optional<core::Clock::time_point> last_reset_sent_;
  std::optional<core::Clock::time_point>
      unanswered_since_;  ///< first battery request with no reply yet
  bool silent_reported_ = false;
  std::optional<core::Clock::time_point> last_running_timeout_error_;
  BaseStats stats_;
  core::LogThrottle internal_error_log_{5.0};
  std::thread loop_;
};

}  // namespace serial_robot_driver::devices::base
