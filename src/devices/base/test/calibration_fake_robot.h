// A small fake robot for calibrate_base's run (test_turn_calibration_run.cpp): the driver writes
// wheel frames at 50 Hz from the last cmd_vel (zero with the e-stop engaged), the chassis turns by
// (1 - slip) of what the frames command, and the IMU reports that turn plus a constant gyro bias
// at 100 Hz. Time is stepped by the test, as the tool steps the run.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/devices/base/turn_calibration_run.h"

namespace calibration_test {

using serial_robot_driver::devices::base::BaseConfig;
using serial_robot_driver::devices::base::BaseTwist;
using serial_robot_driver::devices::base::CalibrationLine;
using serial_robot_driver::devices::base::CalibrationTick;
using serial_robot_driver::devices::base::TurnCalibrationRun;

// The node's default geometry, written out: 0.25 m wheels of 1600 ticks a turn, 0.40 m apart, a
// PID period of 1/50 s. Ticks per period for 1 m/s = 1600 / (pi * 0.25) / 50.
constexpr double kTicksPerPeriodPerMps = 1600.0 / (M_PI * 0.25) / 50.0;
constexpr double kSeparation = 0.40;

struct FakeRobot {
  double slip = 0.15;       ///< the chassis turns by (1 - slip) of the commanded turn
  double gyro_bias = 0.01;  ///< rad/s in every IMU sample
  bool e_stop = false;      ///< the driver writes zero frames; reported on "diagnostics"
  /// The tool sees the e-stop's state (false: it always looks released; an engagement only the
  /// driver's count shows).
  bool e_stop_visible = true;
  uint64_t engagements = 0;              ///< the driver's count of engagements (its e_stop status)
  bool status_values = false;  ///< the tool reads both as the e_stop status's values (text)
  bool telemetry = true;                 ///< IMU samples arrive
  bool frames = true;                    ///< the driver writes wheel frames
  bool ignores_zero = false;             ///< a wedged driver: keeps writing the last moving frame
  std::optional<double> typed_distance;  ///< what the user types at the prompt
  bool prompted = false;                 ///< the run asked for the distance

  BaseTwist command;
  int left = 0, right = 0;                   ///< ticks of the last frame written
  std::optional<double> first_moving_frame;  ///< s

  /// Everything due up to `t` goes to the run.
  void deliver(double t, TurnCalibrationRun& run) {
    for (; next_frame_ <= t; next_frame_ += 0.02) {
      if (!(ignores_zero && command.linear == 0 && command.angular == 0)) {
        const double turn_speed = command.angular * kSeparation / 2;
        left = e_stop ? 0
                      : static_cast<int>(
                            std::lround((command.linear - turn_speed) * kTicksPerPeriodPerMps));
        right = e_stop ? 0
                       : static_cast<int>(
                             std::lround((command.linear + turn_speed) * kTicksPerPeriodPerMps));
      }
      if (!frames) continue;
      if ((left != 0 || right != 0) && !first_moving_frame) first_moving_frame = next_frame_;
      run.addWheelFrame(next_frame_, static_cast<int16_t>(left), static_cast<int16_t>(right));
    }
    for (; next_imu_ <= t; next_imu_ += 0.01) {
      // The chassis follows the last frame, slipping.
      const double commanded_rate = (right - left) / kTicksPerPeriodPerMps / kSeparation;
      if (telemetry) run.addImuRate(next_imu_, commanded_rate * (1 - slip) + gyro_bias);
    }
    if (e_stop && !was_engaged_) ++engagements;
    was_engaged_ = e_stop;
    if (status_values) {  // as the status says them on /diagnostics, among others
      run.setEStopStatusValue("engaged", e_stop && e_stop_visible ? "True" : "False");
      run.setEStopStatusValue("commands refused", "7");
      run.setEStopStatusValue("engagements", std::to_string(engagements));
      return;
    }
    run.setEStopEngaged(e_stop && e_stop_visible);
    run.setEStopEngagements(engagements);
  }
  /// Seconds the base has been moving at `t` (0 before).
  double movingFor(double t) const { return first_moving_frame ? t - *first_moving_frame : 0; }

 private:
  double next_frame_ = 0.0;
  double next_imu_ = 0.003;
  bool was_engaged_ = false;
};

struct Outcome {
  bool finished = false;
  int exit_status = -1;
  double end = 0;  ///< s
  std::string out, err;
  std::vector<std::pair<double, BaseTwist>> commands;  ///< (s, twist) as the run answered them

  static bool isZero(const BaseTwist& twist) { return twist.linear == 0 && twist.angular == 0; }
  bool anyMovingCommandFrom(double t) const {
    for (const auto& [at, twist] : commands) {
      if (at >= t && !isZero(twist)) return true;
    }
    return false;
  }
  std::optional<std::pair<double, BaseTwist>> firstCommandFrom(double t) const {
    for (const auto& command : commands) {
      if (command.first >= t) return command;
    }
    return std::nullopt;
  }
};

/// What a test does at time t (changes the robot); returns a signal to deliver (0: none).
using Script = std::function<int(double t, FakeRobot& robot)>;

/// Steps `run` as the tool does, against `robot`, until it finishes or `limit` s have passed.
inline Outcome runToEnd(TurnCalibrationRun& run, FakeRobot& robot, const Script& script = {},
                        double limit = 120) {
  Outcome outcome;
  for (double t = 0; t < limit;) {
    const int signal = script ? script(t, robot) : 0;
    robot.deliver(t, run);
    CalibrationTick tick;
    tick.now = t;
    tick.stamp_now = t;
    tick.stop_signal = signal;
    tick.command_subscribed = true;
    const auto step = run.step(tick);
    for (const auto& line : step.lines) {
      (line.stream == CalibrationLine::Stream::kErr ? outcome.err : outcome.out) +=
          line.text + "\n";
    }
    if (step.command) {
      robot.command = *step.command;
      outcome.commands.emplace_back(t, *step.command);
    }
    if (step.finished) {
      outcome.finished = true;
      outcome.exit_status = step.exit_status;
      outcome.end = t;
      return outcome;
    }
    if (step.wants_measured_distance) {
      robot.prompted = true;
      run.setMeasuredDistance(robot.typed_distance);
    }
    t += step.next_step_in;
  }
  return outcome;
}

}  // namespace calibration_test
