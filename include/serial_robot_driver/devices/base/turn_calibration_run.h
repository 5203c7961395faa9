// calibrate_base's run (docs/calibration.md), ROS-free: the refusals before anything moves, each
// motion between two rests (hold still until a zero wheel frame confirms it, then move until the
// wheel frames have commanded the goal), the aborts (e-stop, telemetry or wheel frames stopping,
// a signal, a deadline) and the stop on every way out, and the report lines.
//
// A state machine without threads, sleeps or clocks of its own: the tool (src/nodes/
// calibrate_base_main.cpp) hands it what arrived and the time, steps it, publishes the command
// it answers and prints its lines, so that tests step it with a fake robot and a fake clock.
#pragma once

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_controller.h"
#include "serial_robot_driver/devices/base/turn_calibration.h"
#include "serial_robot_driver/devices/base/turn_calibration_options.h"

namespace serial_robot_driver::devices::base {

/// What the tool knows at a step besides the messages that arrived.
struct CalibrationTick {
  double now = 0;         ///< s, a steady clock: deadlines and freshness
  double stamp_now = 0;   ///< s, the clock the message stamps come from (the turn's progress)
  int stop_signal = 0;    ///< a signal (SIGINT, SIGTERM) arrived since the last step; 0: none
  bool connected = true;  ///< false once the tool's connection to ROS is down
  bool command_subscribed = false;  ///< the driver listens to the tool's cmd_vel
};

/// A cmd_vel to publish.
struct BaseTwist {
  double linear = 0;   ///< m/s
  double angular = 0;  ///< rad/s
};

struct CalibrationLine {
  enum class Stream { kOut, kErr, kPrompt };  ///< kPrompt: stdout, no newline, flushed
  Stream stream = Stream::kOut;
  std::string text;
};

/// Shows `lines` as the tool does: kOut on `out` and kErr on `err`, each a line (std::endl), and
/// kPrompt on `out` without a newline, flushed.
void printCalibrationLines(const std::vector<CalibrationLine>& lines, std::ostream& out,
                           std::ostream& err);

/// The answer to a step.
struct CalibrationStep {
  std::optional<BaseTwist> command;  ///< publish this now; unset: nothing this step
  std::vector<CalibrationLine> lines;
  bool wants_measured_distance = false;  ///< read it from the user, then setMeasuredDistance()
  bool finished = false;
  int exit_status = 0;         ///< when finished
  double next_step_in = 0.01;  ///< s until the tool should step again
};

class TurnCalibrationRun {
 public:
  /// `node` is the driver's resolved name, `imu_topic` the resolved IMU topic (for the
  /// messages), `base` the driver's base configuration in force (the ticks are converted exactly
  /// as the node made them).
  TurnCalibrationRun(const CalibrationOptions& options, const std::string& node,
                     const std::string& imu_topic, const BaseConfig& base);

  /// The driver's status name of the e-stop on /diagnostics ("driver_node: e_stop").
  std::string eStopStatusName() const;

  // What arrived since the last step (stamps in s of the tick's stamp_now clock).
  void addImuRate(double stamp, double yaw_rate);
  void addWheelFrame(double stamp, int16_t left_ticks, int16_t right_ticks);
  /// The e-stop's state, from the e_stop topic (every message published on it) and the driver's
  /// e_stop status. An engagement once the run has checked the e-stop, however short, ends it
  /// with the base stopped: it never resumes after a release.
  void setEStopEngaged(bool engaged);
  /// The driver's count of e-stop engagements (its e_stop status): a rise after the check is an
  /// engagement the topic did not show (published before the tool subscribed, say).
  void setEStopEngagements(uint64_t count);
  /// One value of the driver's e_stop status (core::eStopStatus()): its engaged state or its
  /// count of engagements, as above; other values say nothing here.
  void setEStopStatusValue(const std::string& key, const std::string& value);
  /// The distance the user typed; unset when none could be read.
  void setMeasuredDistance(std::optional<double> metres);
  /// An error outside the run (ROS): aborts, stopping the base if it may have moved.
  void fail(const std::string& why);

  CalibrationStep step(const CalibrationTick& tick);
  bool finished() const { return phase_ == Phase::kDone; }

 private:
  enum class Phase {
    kWaitFrame,
    kWaitImu,
    kWaitEStop,
    kWaitSubscriber,
    kHold,
    kMoving,
    kReportTurn,
    kAwaitDistance,
    kStopping,
    kDone
  };
  /// What follows a hold once the base rested.
  enum class AfterHold { kMove, kFinishMotion, kAskDistance, kStopped };
  struct Motion {
    std::string what;
    double linear = 0;
    double angular = 0;
  };

  void runPhase(const CalibrationTick& tick, CalibrationStep& out);
  /// kWaitEStop: refuses an engaged e-stop, else waits for its status and engagement count.
  void checkEStopReleased();
  /// kWaitSubscriber: the first motion once the driver listens to our cmd_vel (or after a wait).
  void startOnceSubscribed(const CalibrationTick& tick);
  /// kHold, kStopping: holds still; a stop with ROS gone leaves it to ~base/cmd_vel_timeout.
  void holdOrGiveUp(const CalibrationTick& tick, CalibrationStep& out);
  /// kAwaitDistance: asks for the measured distance until it is typed (or refused).
  void awaitDistance(CalibrationStep& out);
  void waitFor(bool arrived, double seconds, Phase next, const std::string& timeout_message);
  void startHold(double rest, AfterHold then);
  void hold(CalibrationStep& out);
  void afterHold(CalibrationStep& out);
  void move(const CalibrationTick& tick, CalibrationStep& out);
  void finishMotion();
  void reportTurn();
  void reportDiameter(double measured);
  /// Why a motion must not go on ("" when it may).
  std::string runningProblem() const;
  /// Whether an e-stop engaged since the check (by its message or the driver's count).
  bool eStopEngagedSinceCheck() const;
  void abort(const std::string& message, int exit_status);
  void finish(int exit_status);
  void enterPhase(Phase phase);
  void say(const std::string& text, CalibrationLine::Stream stream = CalibrationLine::Stream::kOut);
  void printSetting(const std::string& key, double value, double configured);

  CalibrationOptions options_;
  std::string node_;
  std::string imu_topic_;
  kinematics::DiffDriveGeometry geometry_;
  int left_direction_ = 1;
  int right_direction_ = 1;

  Phase phase_ = Phase::kWaitFrame;
  bool phase_changed_ = false;
  double now_ = 0;  ///< the current step's tick.now
  double phase_started_ = 0;
  bool started_ = false;
  std::vector<CalibrationLine> pending_lines_;
  int exit_status_ = 0;
  bool moved_ = false;  ///< a motion began: every way out stops the base

  // What arrived; freshness is counted from the step after the arrival.
  bool imu_arrived_ = false, frame_arrived_ = false;
  std::optional<double> last_imu_, last_frame_;  ///< tick.now of the last arrivals
  double last_imu_stamp_ = 0;
  bool last_frame_zero_ = false;
  uint64_t zero_frames_ = 0;
  std::optional<bool> e_stop_engaged_;
  bool e_stop_checked_ = false;  ///< the e-stop was found released before the first motion
  bool e_stop_engaged_since_check_ = false;
  std::optional<uint64_t> engagements_;           ///< the driver's count, latest
  std::optional<uint64_t> engagements_at_check_;  ///< the driver's count when it was checked
  std::optional<std::optional<double>> measured_distance_;  ///< outer unset: not answered yet

  // The current hold.
  double hold_rest_ = 0;
  AfterHold hold_then_ = AfterHold::kMove;
  uint64_t hold_zero_frames_before_ = 0;
  double hold_next_publish_ = 0;
  std::optional<double> hold_rest_until_;

  // The motions: the two turns, then the straight run when asked for.
  std::vector<Motion> motions_;
  std::size_t motion_index_ = 0;
  std::optional<MotionRecorder> recorder_;
  double motion_deadline_ = 0;
  double motion_done_ = 0;  ///< rad or m commanded so far
  double next_progress_ = 0;
  std::vector<MotionRecord> records_;
};

}  // namespace serial_robot_driver::devices::base
