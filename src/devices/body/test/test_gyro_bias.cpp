// The gyro bias estimator: mean and spread, the decision and its limits, the calibrator's refusals
// (no telemetry, not still, motion during the averaging, too few samples, shaken, absurd), what it
// keeps in force, calibrate_on_start and the diagnostics it adds.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <string>
#include <thread>

#include "serial_robot_driver/devices/body/gyro_bias.h"

namespace serial_robot_driver::devices::body {
namespace {

using std::chrono::milliseconds;

const GyroUnits kUnits{0.001, {}};  // 1 mrad/s per LSB, axes as mounted

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

GyroSampleStats samples(const GyroVector& value, std::size_t count) {
  GyroSampleStats stats;
  for (std::size_t i = 0; i < count; ++i) stats.add(value);
  return stats;
}

TEST(GyroSampleStats, MeanAndSampleStandardDeviationPerAxis) {
  GyroSampleStats stats;
  for (double x : {2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0}) stats.add({x, -x, 10.0});
  EXPECT_EQ(stats.count(), 8u);
  EXPECT_DOUBLE_EQ(stats.mean()[0], 5.0);
  EXPECT_DOUBLE_EQ(stats.mean()[1], -5.0);
  EXPECT_DOUBLE_EQ(stats.mean()[2], 10.0);
  EXPECT_NEAR(stats.spread()[0], std::sqrt(32.0 / 7.0), 1e-12);
  EXPECT_NEAR(stats.spread()[1], std::sqrt(32.0 / 7.0), 1e-12);
  EXPECT_DOUBLE_EQ(stats.spread()[2], 0.0);
}

TEST(GyroBiasDecision, AStillMeanUnderTheLimitIsTheBias) {
  const GyroBiasDecision decision = decideGyroBias(samples({20, -15, 30}, 50), kUnits, {});
  ASSERT_TRUE(decision.bias) << decision.problem;
  EXPECT_EQ(*decision.bias, (GyroVector{20, -15, 30}));
}

TEST(GyroBiasDecision, TooFewSamplesAreRefused) {
  const GyroBiasDecision decision = decideGyroBias(samples({20, 0, 0}, 9), kUnits, {});
  EXPECT_FALSE(decision.bias);
  EXPECT_TRUE(contains(decision.problem, "too few IMU samples (9, at least 10 needed)"))
      << decision.problem;
}

TEST(GyroBiasDecision, AMeanOverPointOneRadPerSecondIsTooLargeForABias) {
  // 100 LSB = 0.1 rad/s is the limit itself; 101 LSB is over it, on any axis.
  EXPECT_TRUE(decideGyroBias(samples({100, -100, 100}, 20), kUnits, {}).bias);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    GyroVector raw{0, 0, 0};
    raw[axis] = axis == 1 ? -101 : 101;
    const GyroBiasDecision decision = decideGyroBias(samples(raw, 20), kUnits, {});
    EXPECT_FALSE(decision.bias) << "axis " << axis;
    EXPECT_TRUE(contains(decision.problem, "too large to be a bias")) << decision.problem;
  }
}

TEST(GyroBiasDecision, ALargeSpreadMeansTheRobotWasShaken) {
  GyroSampleStats stats;
  for (int i = 0; i < 40; ++i) stats.add({0, 0, i % 2 ? 80.0 : -80.0});  // mean 0, spread 0.08
  const GyroBiasDecision decision = decideGyroBias(stats, kUnits, {});
  EXPECT_FALSE(decision.bias);
  EXPECT_TRUE(contains(decision.problem, "shaken")) << decision.problem;
}

TEST(GyroBiasDescription, InRadAndDegPerSecondOnTheImuAxes) {
  GyroUnits units = kUnits;
  units.axes.source = {1, 0, 2};  // ~imu/axis_map [-y, x, z]
  units.axes.sign = {-1, 1, 1};
  EXPECT_EQ(describeGyroBias({20, -15, 30}, units),
            "(0.015, 0.02, 0.03) rad/s = (0.8594, 1.146, 1.719) deg/s");
}

/// Limits without the settle time, for the tests about everything else.
GyroCalibrationLimits noSettle() {
  GyroCalibrationLimits limits;
  limits.settle = milliseconds(0);
  return limits;
}

/// A calibrator whose stillness the test sets, fed by a thread that plays a board streaming at
/// 200 Hz (arrival = now), the way the body port's reader thread does.
class GyroCalibratorTest : public ::testing::Test {
 protected:
  explicit GyroCalibratorTest(GyroCalibrationLimits limits = noSettle())
      : calibrator_{[this] {
                      std::lock_guard<std::mutex> lock(still_mutex_);
                      return not_still_;
                    },
                    limits} {}
  ~GyroCalibratorTest() override { stopStreaming(); }

  void startStreaming(GyroVector raw) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      raw_ = raw;
    }
    streaming_ = true;
    feeder_ = std::thread([this] {
      while (streaming_) {
        GyroVector raw;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          raw = raw_;
        }
        in_force_seen_ = calibrator_.onSample(raw, core::Clock::now(), kUnits, 0.3)[2];
        ++frames_fed_;
        std::this_thread::sleep_for(milliseconds(5));
      }
    });
    // The first frames are in before any calibration asks for fresh telemetry.
    while (in_force_seen_ < -1e8) std::this_thread::yield();
  }
  void stopStreaming() {
    streaming_ = false;
    if (feeder_.joinable()) feeder_.join();
  }
  void setRaw(GyroVector raw) {
    std::lock_guard<std::mutex> lock(mutex_);
    raw_ = raw;
  }

  std::mutex mutex_;
  GyroVector raw_{};
  std::atomic<bool> streaming_{false};
  std::atomic<double> in_force_seen_{-1e9};  ///< z of the bias onSample returned last
  std::atomic<int> frames_fed_{0};
  /// Waits until `count` more frames have been fed.
  void waitFrames(int count) {
    const int until = frames_fed_ + count;
    while (frames_fed_ < until) std::this_thread::yield();
  }
  std::thread feeder_;
  std::mutex still_mutex_;
  std::string not_still_;  ///< what the stillness check answers
  GyroBiasCalibrator calibrator_;
  void setNotStill(const std::string& why) {
    std::lock_guard<std::mutex> lock(still_mutex_);
    not_still_ = why;
  }
};

TEST_F(GyroCalibratorTest, RefusedWithoutTelemetryAndNothingChanges) {
  const GyroCalibrationOutcome outcome = calibrator_.calibrate(0.3, kUnits, "imu/calibrate");
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(contains(outcome.message, "imu/calibrate refused: no IMU telemetry"))
      << outcome.message;
  EXPECT_TRUE(contains(outcome.message, "unchanged: not calibrated")) << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{0, 0, 0}));
}

TEST_F(GyroCalibratorTest, AveragesWhileStillThenSubtractsAndSaysWhatWasBefore) {
  startStreaming({20, -15, 30});
  GyroCalibrationOutcome outcome = calibrator_.calibrate(0.3, kUnits, "imu/calibrate");
  ASSERT_TRUE(outcome.success) << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{20, -15, 30}));
  EXPECT_TRUE(contains(outcome.message,
                       "gyro bias (0.02, -0.015, 0.03) rad/s = (1.146, -0.8594, "
                       "1.719) deg/s from "))
      << outcome.message;
  EXPECT_TRUE(contains(outcome.message, "samples over 0.3 s")) << outcome.message;
  EXPECT_TRUE(contains(outcome.message, "before: not calibrated")) << outcome.message;
  // The reader gets the bias to subtract from the next frame on.
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_EQ(in_force_seen_.load(), 30.0);

  setRaw({21, -15, 30});
  outcome = calibrator_.calibrate(0.3, kUnits, "imu/calibrate");
  ASSERT_TRUE(outcome.success) << outcome.message;
  EXPECT_TRUE(contains(outcome.message, "before: (0.02, -0.015, 0.03) rad/s")) << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{21, -15, 30}));
}

TEST_F(GyroCalibratorTest, RefusedWhileNotStillAndWhenMotionStartsDuringTheAveraging) {
  startStreaming({20, -15, 30});
  setNotStill("base: cmd_vel of 0.2 m/s, 0 rad/s in force");
  GyroCalibrationOutcome outcome = calibrator_.calibrate(0.3, kUnits, "imu/calibrate");
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(outcome.not_still);
  EXPECT_TRUE(contains(outcome.message, "not held still (base: cmd_vel of 0.2 m/s"))
      << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{0, 0, 0}));

  setNotStill("");
  waitFrames(2);  // seen still again
  std::thread mover([this] {
    std::this_thread::sleep_for(milliseconds(100));
    setNotStill("the e-stop is engaged");
  });
  outcome = calibrator_.calibrate(0.5, kUnits, "imu/calibrate");
  mover.join();
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(contains(outcome.message, "moved during the averaging: the e-stop is engaged"))
      << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{0, 0, 0}));
}

TEST_F(GyroCalibratorTest, AnAbsurdMeanIsRefusedAndTheBiasInForceKept) {
  startStreaming({20, -15, 30});
  ASSERT_TRUE(calibrator_.calibrate(0.3, kUnits, "imu/calibrate").success);
  setRaw({20, -15, 300});  // 0.3 rad/s: turning, not a bias
  const GyroCalibrationOutcome outcome = calibrator_.calibrate(0.3, kUnits, "imu/calibrate");
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(contains(outcome.message, "too large to be a bias")) << outcome.message;
  EXPECT_TRUE(contains(outcome.message, "unchanged: (0.02, -0.015, 0.03) rad/s"))
      << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{20, -15, 30}));
}

TEST_F(GyroCalibratorTest, TelemetryStoppingDuringTheAveragingIsRefused) {
  startStreaming({20, -15, 30});
  std::thread stopper([this] {
    std::this_thread::sleep_for(milliseconds(30));
    stopStreaming();
  });
  const GyroCalibrationOutcome outcome = calibrator_.calibrate(1.0, kUnits, "imu/calibrate");
  stopper.join();
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(contains(outcome.message, "telemetry stopped during the averaging") ||
              contains(outcome.message, "too few IMU samples"))
      << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{0, 0, 0}));
}

TEST_F(GyroCalibratorTest, CancelEndsAWaitingCalibrationAtOnce) {
  startStreaming({20, -15, 30});
  std::thread canceller([this] {
    std::this_thread::sleep_for(milliseconds(100));
    calibrator_.cancel();
  });
  const auto start = core::Clock::now();
  const GyroCalibrationOutcome outcome = calibrator_.calibrate(30.0, kUnits, "imu/calibrate");
  canceller.join();
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(contains(outcome.message, "shutting down")) << outcome.message;
  EXPECT_LT(core::Clock::now() - start, std::chrono::seconds(20)) << "not the whole 30 s";
}

/// The same, with a settle time of 0.3 s.
class GyroSettleTest : public GyroCalibratorTest {
 protected:
  static GyroCalibrationLimits settling() {
    GyroCalibrationLimits limits;
    limits.settle = milliseconds(300);
    // Every frame looks, so "still" is seen on the next frame (the look's own interval is below).
    limits.idle_motion_look = milliseconds(0);
    return limits;
  }
  GyroSettleTest() : GyroCalibratorTest(settling()) {}
};

// A slow rotation that just ended is not a bias: refused until the robot has been seen still for
// the settle time, the refusal naming what moved last; then it calibrates.
TEST_F(GyroSettleTest, RefusedRightAfterAMotionEndsUntilTheSettleTimeHasPassed) {
  setNotStill("servo_bus: servo(s) 1 set moving");
  startStreaming({20, -15, 30});
  waitFrames(3);  // they see it moving
  setNotStill("");
  waitFrames(2);  // and then still
  GyroCalibrationOutcome outcome = calibrator_.calibrate(0.1, kUnits, "imu/calibrate");
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(outcome.not_still);
  EXPECT_TRUE(contains(outcome.message, "the robot was moving until 0.")) << outcome.message;
  EXPECT_TRUE(contains(outcome.message,
                       "(servo_bus: servo(s) 1 set moving); it must be still for 0.3 s after the "
                       "last motion (settle time)"))
      << outcome.message;
  EXPECT_EQ(calibrator_.bias(), (GyroVector{0, 0, 0}));
  // Once settled it goes through (waited for, bounded). A loaded machine may stretch the feeder's
  // 5 ms sleeps so that a 0.1 s window holds too few samples: that window is tried again too.
  const auto give_up = core::Clock::now() + std::chrono::seconds(10);
  const auto retried = [](const GyroCalibrationOutcome& o) {
    return o.not_still || contains(o.message, "too few IMU samples");
  };
  while (!outcome.success && retried(outcome) && core::Clock::now() < give_up) {
    outcome = calibrator_.calibrate(0.1, kUnits, "imu/calibrate");
  }
  EXPECT_TRUE(outcome.success) << outcome.message;
}

TEST(GyroCalibrateOnStart, StartsOnlyOnceTheRobotHasBeenStillForTheSettleTime) {
  std::string not_still = "body: joint command written 0.10 s ago";
  GyroCalibrationLimits limits;
  limits.settle = milliseconds(400);
  GyroBiasCalibrator calibrator([&] { return not_still; }, limits);
  int reports = 0;
  calibrator.calibrateOnStart([&](const GyroCalibrationOutcome&) { ++reports; });
  const core::Clock::time_point t0{};
  int frame = 0;
  const auto feed = [&](int count, GyroVector raw) {
    for (int i = 0; i < count; ++i, ++frame) {
      calibrator.onSample(raw, t0 + milliseconds(10 * frame), kUnits, 0.5);
    }
  };
  feed(10, {300, 0, 0});  // moving
  not_still = "";
  // Still from frame 10 on: the settle time ends at frame 50, the averaging then takes 0.5 s;
  // the samples before it (the slow end of the motion, 300) are not averaged.
  feed(40, {300, 0, 0});
  feed(50, {5, 6, 7});
  EXPECT_EQ(reports, 0) << "the averaging has only just run its 0.5 s";
  feed(5, {5, 6, 7});
  ASSERT_EQ(reports, 1);
  EXPECT_EQ(calibrator.bias(), (GyroVector{5, 6, 7}));
}

TEST(GyroCalibrateOnStart, WaitsForStillnessRestartsOnMotionAndReportsOnce) {
  std::string not_still = "base: wheels still ramping (0.1, 0.1 m/s)";
  GyroBiasCalibrator calibrator([&] { return not_still; }, noSettle());
  int reports = 0;
  GyroCalibrationOutcome reported;
  calibrator.calibrateOnStart([&](const GyroCalibrationOutcome& outcome) {
    ++reports;
    reported = outcome;
  });
  const core::Clock::time_point t0{};
  int frame = 0;
  // 100 Hz frames with their own arrival times: the automatic averaging runs on them alone.
  const auto feed = [&](int count, GyroVector raw) {
    for (int i = 0; i < count; ++i, ++frame) {
      calibrator.onSample(raw, t0 + milliseconds(10 * frame), kUnits, 0.5);
    }
  };
  feed(20, {300, 0, 0});  // moving: nothing starts
  EXPECT_EQ(reports, 0);
  not_still = "";
  feed(20, {300, 0, 0});  // still for 0.2 s, then the robot moves again: started over
  not_still = "base: cmd_vel of 0.2 m/s, 0 rad/s in force";
  feed(1, {0, 0, 0});
  not_still = "";
  EXPECT_EQ(reports, 0);
  feed(52, {5, 6, 7});  // 0.5 s still from the first still frame on
  ASSERT_EQ(reports, 1);
  EXPECT_TRUE(reported.success) << reported.message;
  EXPECT_EQ(calibrator.bias(), (GyroVector{5, 6, 7})) << "only the samples of the last attempt";
  feed(100, {8, 8, 8});
  EXPECT_EQ(reports, 1) << "once";
  EXPECT_EQ(calibrator.bias(), (GyroVector{5, 6, 7}));
}

TEST(GyroCalibrateOnStart, ARefusalOtherThanMotionIsReportedOnceAndNotRetried) {
  GyroBiasCalibrator calibrator([] { return std::string(); }, noSettle());
  int reports = 0;
  std::string message;
  calibrator.calibrateOnStart([&](const GyroCalibrationOutcome& outcome) {
    ++reports;
    message = outcome.message;
  });
  for (int i = 0; i < 200; ++i) {
    calibrator.onSample({0, 0, 200}, core::Clock::time_point{} + milliseconds(10 * i), kUnits, 0.5);
  }
  EXPECT_EQ(reports, 1);
  EXPECT_TRUE(contains(message, "calibrate_on_start refused: the mean z rate 0.2 rad/s"))
      << message;
  EXPECT_EQ(calibrator.bias(), (GyroVector{0, 0, 0}));
}

TEST(GyroBiasStatus, ShowsTheBiasInForceAndWarnsAboutARefusalUntilAGoodCalibration) {
  GyroBiasCalibrator calibrator([] { return std::string(); }, noSettle());
  core::StatusReport before;
  calibrator.report(before, kUnits);
  EXPECT_EQ(before.level, core::StatusLevel::kOk);
  EXPECT_EQ(*before.find("gyro bias"), "not calibrated");
  EXPECT_EQ(*before.find("gyro bias calibrated"), "never");

  core::StatusReport refused;
  calibrator.calibrate(0.1, kUnits, "imu/calibrate");  // no telemetry
  calibrator.report(refused, kUnits);
  EXPECT_EQ(refused.level, core::StatusLevel::kWarn);
  EXPECT_TRUE(contains(refused.message, "imu/calibrate refused: no IMU telemetry"))
      << refused.message;
  ASSERT_NE(refused.find("gyro calibration refused"), nullptr);

  calibrator.calibrateOnStart([](const GyroCalibrationOutcome&) {});
  for (int i = 0; i < 60; ++i) {
    calibrator.onSample({20, -15, 30}, core::Clock::time_point{} + milliseconds(10 * i), kUnits,
                        0.5);
  }
  core::StatusReport calibrated;
  calibrator.report(calibrated, kUnits);
  EXPECT_EQ(calibrated.level, core::StatusLevel::kOk) << calibrated.message;
  EXPECT_EQ(*calibrated.find("gyro bias"),
            "(0.02, -0.015, 0.03) rad/s = (1.146, -0.8594, 1.719) deg/s");
  EXPECT_TRUE(contains(*calibrated.find("gyro bias calibrated"), "by calibrate_on_start at "));
  EXPECT_EQ(calibrated.find("gyro calibration refused"), nullptr);
}

// With a MotionCheck, a frame asks only the bool: the motion's text is built once when it starts
// (and while a calibration averages), not per frame, and still names it in a refusal.
TEST(GyroBiasCalibratorMotionCheck, FramesAskTheBoolAndNameAMotionOnceWhenItStarts) {
  int texts = 0;
  bool moving = false;
  GyroBiasCalibrator calibrator(
      [&] {
        ++texts;
        return moving ? std::string("base: cmd_vel of 0.2 m/s, 0 rad/s in force") : std::string();
      },
      GyroCalibrationLimits{}, [&] { return moving; });
  const core::Clock::time_point t0 = core::Clock::now() - milliseconds(700);
  int frame = 0;
  const auto feed = [&](int frames) {
    for (int end = frame + frames; frame < end; ++frame) {
      calibrator.onSample({0, 0, 0}, t0 + frame * milliseconds(2), kUnits, 0.3);
    }
  };
  feed(100);
  EXPECT_EQ(texts, 0) << "no text while nothing moves";
  moving = true;
  feed(100);
  EXPECT_EQ(texts, 1) << "named once, on the frame the motion starts";
  moving = false;
  feed(100);
  EXPECT_EQ(texts, 1);
  const GyroCalibrationOutcome outcome = calibrator.calibrate(0.3, kUnits, "imu/calibrate");
  EXPECT_FALSE(outcome.success);
  EXPECT_TRUE(outcome.not_still);
  EXPECT_TRUE(contains(outcome.message, "the robot was moving until")) << outcome.message;
  EXPECT_TRUE(contains(outcome.message, "base: cmd_vel of 0.2 m/s")) << outcome.message;
}

// While nothing averages or waits to start, frames ask whether anything moves once per
// idle_motion_look (50 ms) and keep that answer between; a motion starting between two looks is
// seen (and named) at the next one; a telemetry gap, an armed calibrate_on_start and a refusal
// for motion make the next frame look at once.
TEST(GyroBiasCalibratorMotionCheck, IdleFramesLookEveryFiftyMillisecondsAndKeepTheAnswerBetween) {
  int looks = 0;
  int texts = 0;
  bool moving = false;
  GyroBiasCalibrator calibrator(
      [&] {
        ++texts;
        return moving ? std::string("body: joint command written 0.01 s ago") : std::string();
      },
      GyroCalibrationLimits{},
      [&] {
        ++looks;
        return moving;
      });
  const core::Clock::time_point t0 = core::Clock::now() - milliseconds(5000);
  int frame = 0;
  const auto feed = [&](int frames) {  // 100 Hz
    for (int end = frame + frames; frame < end; ++frame) {
      calibrator.onSample({0, 0, 0}, t0 + frame * milliseconds(10), kUnits, 0.3);
    }
  };
  feed(100);
  EXPECT_EQ(looks, 20) << "frame 0, then every fifth frame";
  moving = true;
  feed(4);  // frames 100-103: 100 looks and names it
  EXPECT_EQ(looks, 21);
  EXPECT_EQ(texts, 1);
  moving = false;
  feed(1);  // frame 104 keeps "moving"
  moving = true;
  feed(5);  // 105 looks: moving again, not a new start, so not named again
  EXPECT_EQ(looks, 22);
  EXPECT_EQ(texts, 1);
  moving = false;
  feed(5);  // 110 looks: still
  EXPECT_EQ(looks, 23);

  // A gap in the telemetry: the first frame after it looks.
  frame += 100;
  feed(1);
  EXPECT_EQ(looks, 24);

  // A refusal for motion between frames: the next frame looks rather than keep "still".
  moving = true;
  const GyroCalibrationOutcome refused = calibrator.calibrate(0.3, kUnits, "imu/calibrate");
  EXPECT_FALSE(refused.success);
  EXPECT_TRUE(refused.not_still);
  const int before = looks;
  feed(1);
  EXPECT_EQ(looks, before + 1);
  moving = false;

  // Armed calibrate_on_start: every frame counts, so every frame looks.
  calibrator.calibrateOnStart([](const GyroCalibrationOutcome&) {});
  const int armed = looks;
  feed(10);
  EXPECT_EQ(looks, armed + 10);
}

}  // namespace
}  // namespace serial_robot_driver::devices::body
