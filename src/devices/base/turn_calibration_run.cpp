#include "serial_robot_driver/devices/base/turn_calibration_run.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "serial_robot_driver/core/e_stop_status.h"

namespace serial_robot_driver::devices::base {

void printCalibrationLines(const std::vector<CalibrationLine>& lines, std::ostream& out,
                           std::ostream& err) {
  for (const CalibrationLine& line : lines) {
    if (line.stream == CalibrationLine::Stream::kErr) err << line.text << std::endl;
    if (line.stream == CalibrationLine::Stream::kOut) out << line.text << std::endl;
    if (line.stream == CalibrationLine::Stream::kPrompt) out << line.text << std::flush;
  }
}

namespace {

constexpr double kArrivalWait = 3.0;       ///< s for a first frame, IMU sample, e-stop status
constexpr double kSubscriberWait = 2.0;    ///< s for the driver to subscribe to our cmd_vel
constexpr double kStopConfirmWait = 3.0;   ///< s for a zero wheel frame after the zero command
constexpr double kZeroRepeat = 0.05;       ///< s between zero commands while holding still
constexpr double kStaleAfter = 0.5;        ///< s without IMU samples or wheel frames mid-motion
constexpr double kProgressEvery = 0.5;     ///< s between progress lines
constexpr double kMotionStep = 0.02;       ///< s between commands while moving
constexpr double kIdleStep = 0.01;         ///< s between steps otherwise
constexpr double kRestBeforePrompt = 0.1;  ///< s still after the straight run, before asking

std::string fixed(double value, int digits = 4) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace

TurnCalibrationRun::TurnCalibrationRun(const CalibrationOptions& options, const std::string& node,
                                       const std::string& imu_topic, const BaseConfig& base)
    : options_(options),
      node_(node),
      imu_topic_(imu_topic),
      geometry_(base.geometry),
      left_direction_(base.left_wheel_direction),
      right_direction_(base.right_wheel_direction) {
  motions_.push_back({"turning counter-clockwise", 0.0, options_.rate});
  motions_.push_back({"turning clockwise", 0.0, -options_.rate});
  if (options_.distance > 0) motions_.push_back({"driving straight", options_.speed, 0.0});
  say("driver " + node_ + ": wheel_separation " + fixed(geometry_.wheel_separation) +
      " m, wheel_diameter " + fixed(geometry_.wheel_diameter) + " m");
}

// The updater's prefix is the node's name without its leading slash.
std::string TurnCalibrationRun::eStopStatusName() const {
  return (node_.empty() || node_[0] != '/' ? node_ : node_.substr(1)) + ": e_stop";
}

void TurnCalibrationRun::addImuRate(double stamp, double yaw_rate) {
  imu_arrived_ = true;
  if (recorder_) recorder_->addImuRate(stamp, yaw_rate);
  last_imu_stamp_ = stamp;
}

void TurnCalibrationRun::addWheelFrame(double stamp, int16_t left_ticks, int16_t right_ticks) {
  frame_arrived_ = true;
  last_frame_zero_ = left_ticks == 0 && right_ticks == 0;
  if (last_frame_zero_) ++zero_frames_;
  if (recorder_) recorder_->addWheelFrame(stamp, left_ticks, right_ticks);
}

void TurnCalibrationRun::setEStopEngaged(bool engaged) {
  e_stop_engaged_ = engaged;
  if (engaged && e_stop_checked_) e_stop_engaged_since_check_ = true;
}

void TurnCalibrationRun::setEStopEngagements(uint64_t count) { engagements_ = count; }

void TurnCalibrationRun::setEStopStatusValue(const std::string& key, const std::string& value) {
  if (key == core::kEStopEngagedKey) setEStopEngaged(value == "True");
  if (key == core::kEStopEngagementsKey) {
    setEStopEngagements(std::strtoull(value.c_str(), nullptr, 10));
  }
}

bool TurnCalibrationRun::eStopEngagedSinceCheck() const {
  return e_stop_engaged_since_check_ ||
         (engagements_ && engagements_at_check_ && *engagements_ > *engagements_at_check_);
}

void TurnCalibrationRun::setMeasuredDistance(std::optional<double> metres) {
  measured_distance_ = metres;
}

void TurnCalibrationRun::fail(const std::string& why) {
  if (phase_ == Phase::kStopping || phase_ == Phase::kDone) return;
  abort(why, kCalibrationExitRefused);
}

CalibrationStep TurnCalibrationRun::step(const CalibrationTick& tick) {
  CalibrationStep out;
  now_ = tick.now;
  if (!started_) {
    started_ = true;
    phase_started_ = now_;
  }
  // Freshness counts from the step that saw the arrival: the tool steps right after delivering.
  if (imu_arrived_) last_imu_ = now_;
  if (frame_arrived_) last_frame_ = now_;
  imu_arrived_ = frame_arrived_ = false;

  const bool stopping = phase_ == Phase::kStopping;
  if (tick.stop_signal != 0) {
    const std::string why = stopSignalMessage(tick.stop_signal);
    if (stopping) {  // a second signal while stopping: give up waiting for the confirmation
      say("calibrate_base: " + why, CalibrationLine::Stream::kErr);
      finish(exit_status_);
    } else if (phase_ != Phase::kDone) {
      abort(why, 128 + tick.stop_signal);
    }
  } else if (!tick.connected && phase_ != Phase::kDone && !stopping) {
    abort("ROS shut down", kCalibrationExitRefused);
  } else if (eStopEngagedSinceCheck() && phase_ != Phase::kDone && !stopping) {
    // Whatever the phase (a hold between motions too), and even when already released.
    abort(
        "aborted: the e-stop engaged; the run never resumes after a release: run "
        "calibrate_base again once it is safe",
        kCalibrationExitRefused);
  }
  // A phase that ends hands over at once, as a sequential run would: the stop on an abort is
  // commanded in the same step that found the reason.
  for (int handovers = 0; handovers < 16; ++handovers) {
    phase_changed_ = false;
    runPhase(tick, out);
    if (!phase_changed_) break;
  }
  out.lines.swap(pending_lines_);
  out.finished = phase_ == Phase::kDone;
  out.exit_status = exit_status_;
  out.next_step_in = phase_ == Phase::kMoving ? kMotionStep : kIdleStep;
  return out;
}

void TurnCalibrationRun::runPhase(const CalibrationTick& tick, CalibrationStep& out) {
  switch (phase_) {
    case Phase::kWaitFrame:
      waitFor(last_frame_.has_value(), kArrivalWait, Phase::kWaitImu,
              "no wheel_command from " + node_ + " in 3 s: is the base enabled and connected?");
      break;
    case Phase::kWaitImu:
      waitFor(last_imu_.has_value(), kArrivalWait, Phase::kWaitEStop,
              "refused: no telemetry on " + imu_topic_ +
                  " in 3 s; the turn is measured with the IMU (is the body enabled and "
                  "streaming?)");
      break;
    case Phase::kWaitEStop:
      checkEStopReleased();
      break;
    case Phase::kWaitSubscriber:
      startOnceSubscribed(tick);
      break;
    case Phase::kHold:
    case Phase::kStopping:
      holdOrGiveUp(tick, out);
      break;
    case Phase::kMoving:
      move(tick, out);
      break;
    case Phase::kReportTurn:
      reportTurn();
      break;
    case Phase::kAwaitDistance:
      awaitDistance(out);
      break;
    case Phase::kDone:
      break;
  }
}

void TurnCalibrationRun::checkEStopReleased() {
  if (e_stop_engaged_.value_or(false)) {
    abort("refused: the e-stop is engaged; release it (e_stop false) and run again",
          kCalibrationExitRefused);
    return;
  }
  // The node's diagnostics come once a second, with its count of engagements: from here on any
  // engagement (a message on e_stop, or the count rising) ends the run.
  waitFor(e_stop_engaged_.has_value() && engagements_.has_value(), kArrivalWait,
          Phase::kWaitSubscriber,
          "no e_stop status from " + node_ +
              " on /diagnostics in 3 s: cannot tell whether the e-stop is engaged");
  if (phase_ == Phase::kWaitSubscriber) {
    e_stop_checked_ = true;
    engagements_at_check_ = engagements_;
  }
}

void TurnCalibrationRun::startOnceSubscribed(const CalibrationTick& tick) {
  if (!tick.command_subscribed && now_ - phase_started_ < kSubscriberWait) return;
  say("turning in place " + fixed(options_.angle, 2) + " rad each way at " +
      fixed(options_.rate, 2) + " rad/s; Ctrl-C stops the base");
  moved_ = true;  // from the first command on, every way out stops the base
  startHold(options_.settle, AfterHold::kMove);
}

void TurnCalibrationRun::holdOrGiveUp(const CalibrationTick& tick, CalibrationStep& out) {
  if (phase_ == Phase::kStopping && !tick.connected) {
    say("calibrate_base: ROS is down; the node's ~base/cmd_vel_timeout stops the base",
        CalibrationLine::Stream::kErr);
    finish(exit_status_);
  } else {
    hold(out);
  }
}

void TurnCalibrationRun::awaitDistance(CalibrationStep& out) {
  if (!measured_distance_) {
    out.wants_measured_distance = true;
  } else if (!*measured_distance_) {
    abort("no distance typed: no wheel_diameter", kCalibrationExitRefused);
  } else {
    reportDiameter(**measured_distance_);
  }
}

void TurnCalibrationRun::waitFor(bool arrived, double seconds, Phase next,
                                 const std::string& timeout_message) {
  if (arrived) {
    enterPhase(next);
  } else if (now_ - phase_started_ >= seconds) {
    abort(timeout_message, kCalibrationExitRefused);
  }
}

void TurnCalibrationRun::startHold(double rest, AfterHold then) {
  enterPhase(Phase::kHold);
  hold_rest_ = rest;
  hold_then_ = then;
  hold_zero_frames_before_ = zero_frames_;
  hold_next_publish_ = -std::numeric_limits<double>::infinity();
  hold_rest_until_.reset();
}

// Zero until a zero frame is written after the hold began (bounded), then `rest` more seconds.
void TurnCalibrationRun::hold(CalibrationStep& out) {
  if (now_ >= hold_next_publish_) {
    out.command = BaseTwist{};
    hold_next_publish_ = now_ + kZeroRepeat;
  }
  if (!hold_rest_until_) {
    if (zero_frames_ > hold_zero_frames_before_ && last_frame_zero_) {
      hold_rest_until_ = now_ + hold_rest_;
    } else if (now_ - phase_started_ >= kStopConfirmWait) {
      const std::string why =
          "no zero wheel frame written within 3 s of the stop; the node's ~base/cmd_vel_timeout "
          "stops the base";
      if (phase_ == Phase::kStopping) {
        say("calibrate_base: " + why, CalibrationLine::Stream::kErr);
        finish(exit_status_);
      } else {
        abort(why, kCalibrationExitRefused);
      }
      return;
    }
  }
  if (hold_rest_until_ && now_ >= *hold_rest_until_) afterHold(out);
}

void TurnCalibrationRun::afterHold(CalibrationStep& out) {
  if (phase_ == Phase::kStopping) {
    say("calibrate_base: base stopped (a zero wheel frame was written)",
        CalibrationLine::Stream::kErr);
    finish(exit_status_);
    return;
  }
  switch (hold_then_) {
    case AfterHold::kMove: {
      const Motion& motion = motions_[motion_index_];
      recorder_.emplace(geometry_, left_direction_, right_direction_);
      const double goal = motion.angular != 0 ? options_.angle : options_.distance;
      const double speed = motion.angular != 0 ? std::abs(motion.angular) : std::abs(motion.linear);
      motion_deadline_ = now_ + goal / speed * 2 + 3;
      motion_done_ = 0;
      next_progress_ = now_;
      enterPhase(Phase::kMoving);
      break;
    }
    case AfterHold::kFinishMotion:
      finishMotion();
      break;
    case AfterHold::kAskDistance:
      if (options_.measured) {
        reportDiameter(*options_.measured);
      } else {
        say("measure the distance the robot travelled and type it in metres: ",
            CalibrationLine::Stream::kPrompt);
        enterPhase(Phase::kAwaitDistance);
        out.wants_measured_distance = true;
      }
      break;
    case AfterHold::kStopped:
      break;
  }
}

// One motion, recorded: a turn until the wheel frames have commanded options_.angle, or a
// straight run until they have commanded options_.distance.
void TurnCalibrationRun::move(const CalibrationTick& tick, CalibrationStep& out) {
  const Motion& motion = motions_[motion_index_];
  const bool turn = motion.angular != 0;
  const double goal = turn ? options_.angle : options_.distance;
  if (const std::string problem = runningProblem(); !problem.empty()) {
    abort(problem, kCalibrationExitRefused);
    return;
  }
  if (now_ > motion_deadline_) {
    abort(motion.what + ": the base did not get there in time (" + fixed(motion_done_, 2) + " of " +
              fixed(goal, 2) + " commanded)",
          kCalibrationExitRefused);
    return;
  }
  out.command = BaseTwist{motion.linear, motion.angular};
  const MotionRecord so_far = recorder_->finish(tick.stamp_now);
  motion_done_ = turn ? std::abs(so_far.commanded_yaw) : so_far.commanded_distance;
  if (now_ >= next_progress_) {
    say(motion.what + ": " + fixed(motion_done_, 2) + " / " + fixed(goal, 2) +
        (turn ? " rad" : " m") + " commanded, IMU " + fixed(so_far.measured_yaw, 2) + " rad");
    next_progress_ += kProgressEvery;
  }
  if (motion_done_ >= goal) startHold(options_.settle, AfterHold::kFinishMotion);
}

void TurnCalibrationRun::finishMotion() {
  if (const std::string problem = runningProblem(); !problem.empty()) {
    abort(problem, kCalibrationExitRefused);
    return;
  }
  const Motion& motion = motions_[motion_index_];
  const MotionRecord record = recorder_->finish(last_imu_stamp_);
  recorder_.reset();
  if (motion.angular != 0) {
    say(motion.what + ": done, commanded " + fixed(record.commanded_yaw, 3) +
        " rad, IMU measured " + fixed(record.measured_yaw, 3) + " rad (" +
        std::to_string(record.imu_samples) + " samples)");
  } else {
    say(motion.what + ": done, commanded " + fixed(record.commanded_distance, 3) + " m");
  }
  records_.push_back(record);
  ++motion_index_;
  if (motion_index_ == 1) {
    startHold(options_.settle, AfterHold::kMove);  // the clockwise turn
  } else if (motion_index_ == 2) {
    enterPhase(Phase::kReportTurn);
  } else {
    startHold(kRestBeforePrompt, AfterHold::kAskDistance);
  }
}

void TurnCalibrationRun::reportTurn() {
  const auto turn = calibrateTurn(records_[0], records_[1], geometry_.wheel_separation);
  if (!turn.value) {
    abort("refused: " + turn.error, kCalibrationExitRefused);
    return;
  }
  say("measured/commanded turn " + fixed(turn.value->ratio, 3) + " (counter-clockwise " +
      fixed(turn.value->ratio_ccw, 3) + ", clockwise " + fixed(turn.value->ratio_cw, 3) +
      ", gyro bias " + fixed(turn.value->gyro_bias, 4) + " rad/s)");
  printSetting("wheel_separation", turn.value->effective_separation, geometry_.wheel_separation);
  if (motions_.size() > 2) {
    startHold(options_.settle, AfterHold::kMove);  // the straight run
  } else {
    finish(0);
  }
}

void TurnCalibrationRun::reportDiameter(double measured) {
  const auto diameter = calibrateDiameter(records_[2], measured, geometry_.wheel_diameter);
  if (!diameter.value) {
    abort("refused: " + diameter.error, kCalibrationExitRefused);
    return;
  }
  say("measured/commanded distance " + fixed(diameter.value->ratio, 3));
  printSetting("wheel_diameter", diameter.value->effective_diameter, geometry_.wheel_diameter);
  const double scale = diameter.value->effective_diameter / geometry_.wheel_diameter;
  const auto turn = calibrateTurn(records_[0], records_[1], geometry_.wheel_separation, scale);
  // Refused only for a diameter itself refused above: the ratios do not depend on the scale.
  if (turn.value) {
    say("with that wheel_diameter, the turns give wheel_separation " +
        fixed(turn.value->effective_separation) + " (set both)");
  }
  finish(0);
}

std::string TurnCalibrationRun::runningProblem() const {
  if (e_stop_engaged_.value_or(false)) return "aborted: the e-stop engaged";
  if (!last_imu_ || now_ - *last_imu_ > kStaleAfter) {
    return "aborted: telemetry stopped (no imu/data for 0.5 s)";
  }
  if (!last_frame_ || now_ - *last_frame_ > kStaleAfter) {
    return "aborted: the node stopped writing wheel frames (no wheel_command for 0.5 s)";
  }
  return "";
}

// Every way out: the reason, then (once the base may have moved) zero until a zero frame.
void TurnCalibrationRun::abort(const std::string& message, int exit_status) {
  say("calibrate_base: " + message, CalibrationLine::Stream::kErr);
  exit_status_ = exit_status;
  recorder_.reset();
  if (!moved_) {
    finish(exit_status);
    return;
  }
  startHold(0.0, AfterHold::kStopped);
  phase_ = Phase::kStopping;
}

void TurnCalibrationRun::finish(int exit_status) {
  exit_status_ = exit_status;
  enterPhase(Phase::kDone);
}

void TurnCalibrationRun::enterPhase(Phase phase) {
  phase_ = phase;
  phase_started_ = now_;
  phase_changed_ = true;
}

void TurnCalibrationRun::say(const std::string& text, CalibrationLine::Stream stream) {
  pending_lines_.push_back({stream, text});
}

void TurnCalibrationRun::printSetting(const std::string& key, double value, double configured) {
  say("effective " + key + ": " + fixed(value) + " m (configured " + fixed(configured) + " m)");
  say("  try it now:  rosrun dynamic_reconfigure dynparam set " + node_ + "/base " + key + " " +
      fixed(value));
  say("  keep it:     in your config file, under base:   " + key + ": " + fixed(value));
}

}  // namespace serial_robot_driver::devices::base
