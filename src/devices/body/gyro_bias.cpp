#include "serial_robot_driver/devices/body/gyro_bias.h"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <utility>

#include "serial_robot_driver/core/clock.h"

namespace serial_robot_driver::devices::body {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr const char* kAxisNames[3] = {"x", "y", "z"};

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

/// "(a, b, c)" with 4 significant digits.
std::string triple(const GyroVector& values) {
  return "(" + format("%.4g", values[0]) + ", " + format("%.4g", values[1]) + ", " +
         format("%.4g", values[2]) + ")";
}

std::string utc(std::chrono::system_clock::time_point when) {
  const std::time_t seconds = std::chrono::system_clock::to_time_t(when);
  std::tm parts{};
  gmtime_r(&seconds, &parts);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &parts);
  return text;
}

}  // namespace

GyroVector GyroUnits::toImuRadPerSecond(const GyroVector& raw) const {
  GyroVector imu{};
  for (std::size_t i = 0; i < 3; ++i) imu[i] = axes.sign[i] * raw[axes.source[i]] * gyro_scale;
  return imu;
}

void GyroSampleStats::add(const GyroVector& raw) {
  ++count_;
  for (std::size_t i = 0; i < 3; ++i) {
    const double delta = raw[i] - mean_[i];
    mean_[i] += delta / static_cast<double>(count_);
    squares_[i] += delta * (raw[i] - mean_[i]);
  }
}

GyroVector GyroSampleStats::spread() const {
  GyroVector spread{};
  if (count_ < 2) return spread;
  for (std::size_t i = 0; i < 3; ++i) {
    spread[i] = std::sqrt(squares_[i] / static_cast<double>(count_ - 1));
  }
  return spread;
}

GyroBiasDecision decideGyroBias(const GyroSampleStats& stats, const GyroUnits& units,
                                const GyroCalibrationLimits& limits) {
  GyroBiasDecision decision;
  if (stats.count() < limits.min_samples) {
    decision.problem = "too few IMU samples (" + std::to_string(stats.count()) + ", at least " +
                       std::to_string(limits.min_samples) +
                       " needed): is the board streaming telemetry?";
    return decision;
  }
  const GyroVector spread = units.toImuRadPerSecond(stats.spread());
  const GyroVector mean = units.toImuRadPerSecond(stats.mean());
  for (std::size_t i = 0; i < 3; ++i) {
    if (std::abs(spread[i]) > limits.max_spread) {
      decision.problem = std::string("the gyro's ") + kAxisNames[i] + " varied by " +
                         format("%.3g", std::abs(spread[i])) + " rad/s (standard deviation; " +
                         format("%.3g", limits.max_spread) +
                         " at most): the robot was shaken or bumped";
      return decision;
    }
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (std::abs(mean[i]) > limits.max_bias) {
      decision.problem = std::string("the mean ") + kAxisNames[i] + " rate " +
                         format("%.4g", mean[i]) + " rad/s is over " +
                         format("%.3g", limits.max_bias) +
                         " rad/s: too large to be a bias (was the robot turning?)";
      return decision;
    }
  }
  decision.bias = stats.mean();
  return decision;
}

std::string describeGyroBias(const GyroVector& raw, const GyroUnits& units) {
  const GyroVector rad = units.toImuRadPerSecond(raw);
  const GyroVector deg{rad[0] * kRadToDeg, rad[1] * kRadToDeg, rad[2] * kRadToDeg};
  return triple(rad) + " rad/s = " + triple(deg) + " deg/s";
}

GyroBiasCalibrator::GyroBiasCalibrator(StillnessCheck still, GyroCalibrationLimits limits,
                                       MotionCheck moving)
    : still_(std::move(still)), moving_(std::move(moving)), limits_(limits) {}

std::optional<std::string> GyroBiasCalibrator::motionNow(bool name_it) const {
  if (moving_ && !moving_()) return std::nullopt;
  if (moving_ && !name_it) return std::string();
  std::string why = still_();
  if (why.empty()) return std::nullopt;  // (it stopped between the two questions)
  return why;
}

bool GyroBiasCalibrator::looksForMotionLocked(core::Clock::time_point arrival,
                                              bool after_gap) const {
  // Averaging, or waiting to start (calibrate_on_start): every frame counts, so every frame looks.
  if (session_ || start_report_ || after_gap || !last_look_) return true;
  return arrival < *last_look_ || arrival - *last_look_ >= limits_.idle_motion_look;
}

void GyroBiasCalibrator::noteMotionLocked(const std::optional<std::string>& motion,
                                          core::Clock::time_point arrival, bool after_gap) {
  if (motion) {
    still_since_.reset();
    if (!motion->empty()) last_motion_ = *motion;
  } else if (!still_since_ || after_gap) {
    if (after_gap) last_motion_.clear();  // still since the gap, for all anyone knows
    still_since_ = arrival;
  }
}

GyroVector GyroBiasCalibrator::onSample(const GyroVector& raw, core::Clock::time_point arrival,
                                        const GyroUnits& units, double seconds) {
  bool after_gap = false;
  bool name_motion = false;
  bool look = false;
  bool kept_moving = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    after_gap = !last_arrival_ || arrival - *last_arrival_ > limits_.max_telemetry_age;
    last_arrival_ = arrival;
    // What moves is named only where it is kept: a motion starting, or a calibration under way.
    name_motion = still_since_ || session_ || last_motion_.empty();
    look = looksForMotionLocked(arrival, after_gap);
    kept_moving = last_look_moved_;
  }
  // Asked calibrating or not (the settle time counts from the end of a motion), without mutex_
  // held: the check takes the other devices' locks. A frame that does not look keeps the last
  // answer, which changes nothing noteMotionLocked() keeps.
  std::optional<std::string> motion;
  if (look) {
    motion = motionNow(name_motion);
  } else if (kept_moving) {
    motion = std::string();
  }
  std::optional<GyroCalibrationOutcome> start_outcome;
  StartReport report;
  GyroVector bias{};
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (look) {
      last_look_ = arrival;
      last_look_moved_ = motion.has_value();
    }
    noteMotionLocked(motion, arrival, after_gap);
    if (!session_ && start_report_ && !cancelled_ && !motion && settledLocked(arrival)) {
      session_ = Session{"calibrate_on_start",
                         arrival,
                         arrival + core::fromSeconds(seconds),
                         seconds,
                         {},
                         {},
                         true};
    }
    if (session_ && arrival >= session_->begin) {
      if (motion && session_->not_still.empty()) {
        session_->not_still = !motion->empty() ? *motion : last_motion_;
        if (session_->not_still.empty()) session_->not_still = "the robot moved";
      }
      if (session_->automatic) {
        if (!session_->not_still.empty()) {
          session_.reset();  // started again from the first frame the robot is still
        } else if (arrival >= session_->end) {
          start_outcome = finishLocked(*session_, units);
          session_.reset();
          report = std::move(start_report_);
          start_report_ = nullptr;
        } else {
          session_->stats.add(raw);
        }
      } else if (arrival <= session_->end) {
        session_->stats.add(raw);
        if (!session_->not_still.empty()) wake_.notify_all();
      }
    }
    if (in_force_) bias = in_force_->bias;
  }
  if (start_outcome && report) report(*start_outcome);
  return bias;
}

GyroCalibrationOutcome GyroBiasCalibrator::calibrate(double seconds, const GyroUnits& units,
                                                     const std::string& how) {
  const std::string not_still = still_();
  std::unique_lock<std::mutex> lock(mutex_);
  if (cancelled_) return {false, how + " refused: the driver is shutting down", false};
  if (session_) {
    return {false, how + " refused: a calibration is already under way (" + session_->how + ")",
            false};
  }
  if (!not_still.empty()) {
    // Seen moving now, between frames maybe: the settle time counts from after this too.
    still_since_.reset();
    last_motion_ = not_still;
    last_look_.reset();  // the next frame looks again, rather than keep an answer of "still"
    return refuseLocked(how, "the robot is not held still (" + not_still + ")", units, true);
  }
  const core::Clock::time_point now = core::Clock::now();
  if (!last_arrival_ || now - *last_arrival_ > limits_.max_telemetry_age) {
    const std::string since =
        last_arrival_
            ? "the last frame arrived " +
                  format("%.1f", std::chrono::duration<double>(now - *last_arrival_).count()) +
                  " s ago"
            : std::string("no frame received yet");
    return refuseLocked(how, "no IMU telemetry (" + since + ")", units, false);
  }
  if (!settledLocked(now)) return refuseLocked(how, unsettledLocked(now), units, true);
  session_ = Session{how, now, now + core::fromSeconds(seconds), seconds, {}, {}, false};
  // Between frames too the robot may start moving (or telemetry stop while it moves): look every
  // 50 ms, not only when a frame arrives.
  while (!cancelled_ && session_->not_still.empty() && core::Clock::now() < session_->end) {
    wake_.wait_until(lock,
                     std::min(session_->end, core::Clock::now() + std::chrono::milliseconds(50)));
    if (cancelled_ || !session_->not_still.empty()) break;
    lock.unlock();
    const std::string moving = still_();
    lock.lock();
    if (!moving.empty() && session_->not_still.empty()) session_->not_still = moving;
  }
  const Session session = std::move(*session_);
  session_.reset();
  if (cancelled_) return {false, how + " refused: the driver is shutting down", false};
  if (!session.not_still.empty()) {
    return refuseLocked(how, "the robot moved during the averaging: " + session.not_still, units,
                        true);
  }
  if (!last_arrival_ || session.end - *last_arrival_ > limits_.max_telemetry_age) {
    return refuseLocked(how,
                        "IMU telemetry stopped during the averaging (" +
                            std::to_string(session.stats.count()) + " samples)",
                        units, false);
  }
  GyroCalibrationOutcome outcome = finishLocked(session, units);
  // A bias asked for by hand is not replaced by calibrate_on_start's later.
  if (outcome.success) start_report_ = nullptr;
  return outcome;
}

void GyroBiasCalibrator::calibrateOnStart(StartReport report) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!cancelled_) start_report_ = std::move(report);
}

void GyroBiasCalibrator::cancel() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cancelled_ = true;
    start_report_ = nullptr;
  }
  wake_.notify_all();
}

GyroVector GyroBiasCalibrator::bias() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return in_force_ ? in_force_->bias : GyroVector{};
}

void GyroBiasCalibrator::report(core::StatusReport& status, const GyroUnits& units) const {
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("gyro bias", in_force_ ? describeGyroBias(in_force_->bias, units) : "not calibrated");
  status.add("gyro bias calibrated",
             in_force_ ? "by " + in_force_->how + " at " + utc(in_force_->when) + " (" +
                             std::to_string(in_force_->samples) + " samples over " +
                             format("%g", in_force_->seconds) + " s)"
                       : std::string("never"));
  if (session_) {
    status.add("gyro calibration", "averaging (" + session_->how + ")");
  } else if (start_report_) {
    status.add("gyro calibration", "calibrate_on_start: waiting for telemetry and a still robot");
  }
  if (!last_refusal_.empty()) {
    status.add("gyro calibration refused", last_refusal_);
    status.mergeSummary(core::StatusLevel::kWarn, last_refusal_);
  }
}

GyroCalibrationOutcome GyroBiasCalibrator::finishLocked(const Session& session,
                                                        const GyroUnits& units) {
  const GyroBiasDecision decision = decideGyroBias(session.stats, units, limits_);
  if (!decision.bias) return refuseLocked(session.how, decision.problem, units, false);
  const std::string before = inForceLocked(units);
  in_force_ = InForce{*decision.bias, session.stats.count(), session.seconds, session.how,
                      std::chrono::system_clock::now()};
  last_refusal_.clear();
  return {true,
          "gyro bias " + describeGyroBias(*decision.bias, units) + " from " +
              std::to_string(session.stats.count()) + " samples over " +
              format("%g", session.seconds) +
              " s, subtracted from imu/data from now on; before: " + before,
          false};
}

bool GyroBiasCalibrator::settledLocked(core::Clock::time_point now) const {
  return still_since_ && now - *still_since_ >= limits_.settle;
}

std::string GyroBiasCalibrator::unsettledLocked(core::Clock::time_point now) const {
  const std::string settle =
      format("%g", std::chrono::duration<double>(limits_.settle).count()) + " s";
  // Unset: no frame has found it still since the motion the last one saw.
  const std::string until =
      still_since_
          ? format("%.2f", std::chrono::duration<double>(now - *still_since_).count()) + " s ago"
          : std::string("just now");
  if (last_motion_.empty()) {
    return "IMU telemetry (re)started only " + until + ": the robot must be seen still for " +
           settle + " first (settle time)";
  }
  return "the robot was moving until " + until + " (" + last_motion_ + "); it must be still for " +
         settle + " after the last motion (settle time)";
}

std::string GyroBiasCalibrator::inForceLocked(const GyroUnits& units) const {
  if (!in_force_) return "not calibrated";
  return describeGyroBias(in_force_->bias, units) + " by " + in_force_->how + " at " +
         utc(in_force_->when);
}

GyroCalibrationOutcome GyroBiasCalibrator::refuseLocked(const std::string& how,
                                                        const std::string& why,
                                                        const GyroUnits& units, bool not_still) {
  last_refusal_ = how + " refused: " + why;
  return {false, last_refusal_ + "; the bias in force is unchanged: " + inForceLocked(units),
          not_still};
}

}  // namespace serial_robot_driver::devices::body
