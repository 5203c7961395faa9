// The turning calibration's estimator: wheel frames and IMU rates integrated over a turn, both
// directions combined (a constant gyro bias cancels), absurd results refused, and the
// straight-line diameter check.
#include <gtest/gtest.h>

#include <cmath>

#include "serial_robot_driver/devices/base/turn_calibration.h"

namespace {

using namespace serial_robot_driver::devices::base;
using serial_robot_driver::kinematics::DiffDriveGeometry;

// The node's defaults: 0.25 m wheels, 1600 ticks a turn, PID at 50 Hz, 0.40 m apart.
const DiffDriveGeometry kGeometry{0.25, 0.40, 1600, 50};

// Wheel speed (m/s) of `ticks` per PID period, written out from the protocol: a wheel turn is 1600
// ticks and pi * 0.25 m, the base runs 50 periods a second.
double speedOf(int ticks) { return ticks * M_PI * 0.25 / 1600.0 * 50.0; }

struct SimulatedTurn {
  int ticks = 40;             ///< right wheel forward, left backward (negative: clockwise)
  double turn_seconds = 1.5;  ///< wheel frames with these ticks, at rest before and after
  double slip = 0.15;         ///< the chassis turns by (1 - slip) of the commanded turn
  double gyro_bias = 0.0;     ///< rad/s added to every IMU sample
  double rest_seconds = 0.5;  ///< still before and after the turn
  double imu_period = 0.02;
};

// One turn as the tool sees it: wheel frames at 50 Hz and IMU samples at their own phase, both
// starting and ending at rest.
MotionRecord record(const SimulatedTurn& turn) {
  MotionRecorder recorder(kGeometry);
  const double end = turn.rest_seconds * 2 + turn.turn_seconds;
  const double true_rate = 2 * speedOf(turn.ticks) / 0.40 * (1 - turn.slip);
  for (double t = 0; t < end; t += 0.02) {
    const bool turning = t >= turn.rest_seconds && t < turn.rest_seconds + turn.turn_seconds - 1e-9;
    const int ticks = turning ? turn.ticks : 0;
    recorder.addWheelFrame(t, static_cast<int16_t>(-ticks), static_cast<int16_t>(ticks));
  }
  for (double t = 0.007; t < end; t += turn.imu_period) {
    const bool turning = t >= turn.rest_seconds && t < turn.rest_seconds + turn.turn_seconds;
    recorder.addImuRate(t, (turning ? true_rate : 0.0) + turn.gyro_bias);
  }
  return recorder.finish(end);
}

TEST(MotionRecorder, IntegratesTheWheelFramesAndTheImuOverTheWindow) {
  SimulatedTurn turn;
  turn.slip = 0.0;
  const MotionRecord r = record(turn);
  const double commanded_rate = 2 * speedOf(40) / 0.40;  // 4.909 rad/s
  EXPECT_NEAR(r.commanded_yaw, commanded_rate * 1.5, 1e-9);
  EXPECT_NEAR(r.commanded_distance, 0.0, 1e-12);
  // The IMU samples see the same turn, within one sample at each edge.
  EXPECT_NEAR(r.measured_yaw, commanded_rate * 1.5, commanded_rate * 0.02);
  EXPECT_EQ(r.wheel_frames, 125u);
  EXPECT_EQ(r.imu_samples, 125u);
  EXPECT_NEAR(r.longest_imu_gap, 0.02, 1e-9);
}

TEST(MotionRecorder, AFrameHoldsOnlyUntilTheBaseTimesOut) {
  MotionRecorder recorder(kGeometry, 1, 1, 1.0);
  recorder.addWheelFrame(0.0, 20, 20);
  recorder.addWheelFrame(5.0, 0, 0);  // the base stopped itself 1 s after the first frame
  const MotionRecord r = recorder.finish(6.0);
  EXPECT_NEAR(r.commanded_distance, speedOf(20) * 1.0, 1e-12);
  EXPECT_NEAR(r.commanded_yaw, 0.0, 1e-12);
}

TEST(MotionRecorder, CommandedYawSoFarHoldsTheLastFrameUntilNow) {
  MotionRecorder recorder(kGeometry);
  recorder.addWheelFrame(0.0, -10, 10);
  const double rate = 2 * speedOf(10) / 0.40;
  EXPECT_NEAR(recorder.commandedYawUntil(0.5), rate * 0.5, 1e-12);
  recorder.addWheelFrame(0.25, 0, 0);
  EXPECT_NEAR(recorder.commandedYawUntil(0.5), rate * 0.25, 1e-12);
}

TEST(MotionRecorder, WireTicksOfAReversedWheelTurnBackIntoTheRobotsOwn) {
  // The left wheel is wired the other way round (~base/left_wheel_direction -1): a turn to the
  // left, left wheel backward, goes out as +40 on both wheels.
  MotionRecorder recorder(kGeometry, -1, 1);
  recorder.addWheelFrame(0.0, 40, 40);
  const MotionRecord r = recorder.finish(1.0);
  EXPECT_NEAR(r.commanded_yaw, 2 * speedOf(40) / 0.40, 1e-12);
  EXPECT_NEAR(r.commanded_distance, 0.0, 1e-12);
}

TEST(TurnCalibration, SlipGivesTheEffectiveSeparation) {
  SimulatedTurn ccw;
  SimulatedTurn cw;
  cw.ticks = -40;
  const auto result = calibrateTurn(record(ccw), record(cw), 0.40);
  ASSERT_TRUE(result.value) << result.error;
  EXPECT_NEAR(result.value->ratio, 0.85, 0.01);
  EXPECT_NEAR(result.value->effective_separation, 0.40 / 0.85, 0.40 / 0.85 * 0.01);
  EXPECT_NEAR(result.value->gyro_bias, 0.0, 0.005);
}

TEST(TurnCalibration, BothDirectionsCancelAConstantGyroBias) {
  SimulatedTurn ccw;
  ccw.gyro_bias = 0.1;
  SimulatedTurn cw = ccw;
  cw.ticks = -40;
  cw.rest_seconds = 2.0;  // the turns need not take the same time: the mean of both is off
  const MotionRecord a = record(ccw);
  const MotionRecord b = record(cw);
  const auto result = calibrateTurn(a, b, 0.40);
  ASSERT_TRUE(result.value) << result.error;
  // Each direction alone is off by bias * duration / commanded turn (about 0.035 here) ...
  EXPECT_GT(result.value->ratio_ccw - 0.85, 0.02);
  EXPECT_GT(0.85 - result.value->ratio_cw, 0.02);
  // ... both together recover the slip and the bias itself.
  EXPECT_NEAR(result.value->ratio, 0.85, 0.005);
  EXPECT_NEAR(result.value->gyro_bias, 0.1, 0.002);
  EXPECT_NEAR(result.value->effective_separation, 0.40 / 0.85, 0.40 / 0.85 * 0.006);
}

TEST(TurnCalibration, AWheelDiameterCorrectionScalesTheSeparation) {
  SimulatedTurn ccw;
  SimulatedTurn cw;
  cw.ticks = -40;
  const auto result = calibrateTurn(record(ccw), record(cw), 0.40, 1.1);
  ASSERT_TRUE(result.value) << result.error;
  EXPECT_NEAR(result.value->effective_separation, 0.40 * 1.1 / result.value->ratio, 1e-12);
}

Checked<TurnCalibration> calibrateWith(SimulatedTurn ccw, SimulatedTurn cw) {
  if (cw.ticks > 0) cw.ticks = -cw.ticks;
  return calibrateTurn(record(ccw), record(cw), 0.40);
}

TEST(TurnCalibration, RefusesARatioOutsideHalfToOneAndAHalf) {
  SimulatedTurn slippery;
  slippery.slip = 0.6;  // measured/commanded 0.4
  const auto result = calibrateWith(slippery, slippery);
  EXPECT_FALSE(result.value);
  EXPECT_NE(result.error.find("0.400 is outside 0.50..1.50"), std::string::npos) << result.error;
  SimulatedTurn just_inside;
  just_inside.slip = 0.45;
  EXPECT_TRUE(calibrateWith(just_inside, just_inside).value);
}

TEST(TurnCalibration, RefusesAnImuTurningTheOtherWay) {
  SimulatedTurn upside_down;
  upside_down.slip = 1.85;  // the IMU reports -0.85 of the commanded turn
  const auto result = calibrateWith(upside_down, upside_down);
  EXPECT_FALSE(result.value);
  EXPECT_NE(result.error.find("opposite sign"), std::string::npos) << result.error;
}

TEST(TurnCalibration, RefusesTooFewImuSamples) {
  SimulatedTurn sparse;
  sparse.imu_period = 0.2;  // 13 samples in 2.5 s
  const auto result = calibrateWith(sparse, SimulatedTurn{});
  EXPECT_FALSE(result.value);
  EXPECT_NE(result.error.find("too few IMU samples in the counter-clockwise turn"),
            std::string::npos)
      << result.error;
}

TEST(TurnCalibration, RefusesATurnWhoseTelemetryStopped) {
  SimulatedTurn ccw;
  SimulatedTurn cw;
  cw.ticks = -40;
  MotionRecord gap = record(cw);
  gap.longest_imu_gap = 0.8;
  const auto result = calibrateTurn(record(ccw), gap, 0.40);
  EXPECT_FALSE(result.value);
  EXPECT_NE(result.error.find("telemetry stopped during the clockwise turn"), std::string::npos)
      << result.error;
}

TEST(TurnCalibration, RefusesDirectionsThatDisagree) {
  SimulatedTurn grippy;
  grippy.slip = 0.0;
  SimulatedTurn slippery;
  slippery.slip = 0.3;
  const auto result = calibrateWith(grippy, slippery);
  EXPECT_FALSE(result.value);
  EXPECT_NE(result.error.find("the two directions disagree"), std::string::npos) << result.error;
  SimulatedTurn close = grippy;
  close.slip = 0.1;
  EXPECT_TRUE(calibrateWith(grippy, close).value);
}

TEST(TurnCalibration, RefusesATurnThatWasNeverCommanded) {
  SimulatedTurn stopped;
  stopped.ticks = 0;  // e.g. the e-stop held the base at zero speed
  const auto result = calibrateWith(SimulatedTurn{}, stopped);
  EXPECT_FALSE(result.value);
  EXPECT_NE(result.error.find("hardly commanded to turn clockwise"), std::string::npos)
      << result.error;
}

TEST(DiameterCalibration, TheMeasuredDistanceGivesTheEffectiveDiameter) {
  MotionRecorder recorder(kGeometry);
  for (int i = 0; i < 100; ++i) recorder.addWheelFrame(i * 0.02, 20, 20);
  recorder.addWheelFrame(2.0, 0, 0);
  const MotionRecord straight = recorder.finish(2.5);
  EXPECT_NEAR(straight.commanded_distance, speedOf(20) * 2.0, 1e-9);  // 0.982 m
  const auto result = calibrateDiameter(straight, 0.95, 0.25);
  ASSERT_TRUE(result.value) << result.error;
  EXPECT_NEAR(result.value->ratio, 0.95 / (speedOf(20) * 2.0), 1e-9);
  EXPECT_NEAR(result.value->effective_diameter, 0.25 * 0.95 / (speedOf(20) * 2.0), 1e-9);

  const auto absurd = calibrateDiameter(straight, 0.3, 0.25);  // a typo, or centimetres
  EXPECT_FALSE(absurd.value);
  EXPECT_NE(absurd.error.find("a measuring mistake"), std::string::npos) << absurd.error;
  EXPECT_FALSE(calibrateDiameter(recorder.finish(0.0), 0.0, 0.25).value);
}

}  // namespace
