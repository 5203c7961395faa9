// Differential-drive kinematics and tick quantization (docs/protocols.md, section 1 "Wheel speed
// unit").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <tuple>

#include "serial_robot_driver/kinematics/diff_drive.h"

namespace serial_robot_driver::kinematics {
namespace {

constexpr double kTol = 1e-9;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Defaults from the spec: diameter 0.25 m, 1600 ticks/rev, PID 50 Hz, separation 0.40 m.
DiffDriveGeometry defaultGeometry() { return DiffDriveGeometry{}; }

TEST(DiffDriveGeometry, TicksPerMeterMatchesTheSpec) {
  const DiffDriveGeometry geometry = defaultGeometry();
  EXPECT_NEAR(geometry.ticksPerMeter(), 2037.18, 0.01);
  EXPECT_NEAR(geometry.ticksPerPeriodPerMps(), 2037.18 / 50.0, 0.001);
}

TEST(DiffDriveTwist, StraightDrivesBothWheelsEqually) {
  const WheelSpeeds speeds = wheelSpeedsFromTwist(defaultGeometry(), 0.5, 0.0);
  EXPECT_NEAR(speeds.x(), 0.5, kTol);
  EXPECT_NEAR(speeds.y(), 0.5, kTol);
}

TEST(DiffDriveTwist, TurnInPlaceGivesOppositeEqualSpeeds) {
  // omega * sep / 2 = 1.0 * 0.40 / 2 = 0.2 m/s; positive omega (counter-clockwise): right forward.
  const WheelSpeeds speeds = wheelSpeedsFromTwist(defaultGeometry(), 0.0, 1.0);
  EXPECT_NEAR(speeds.x(), -0.2, kTol);
  EXPECT_NEAR(speeds.y(), 0.2, kTol);
}

TEST(DiffDriveTwist, ArcSpeedsMatchTheTurnRadius) {
  // v = 0.3, omega = 0.5: left 0.3 - 0.1 = 0.2, right 0.3 + 0.1 = 0.4; radius v/omega = 0.6 m.
  const WheelSpeeds speeds = wheelSpeedsFromTwist(defaultGeometry(), 0.3, 0.5);
  EXPECT_NEAR(speeds.x(), 0.2, kTol);
  EXPECT_NEAR(speeds.y(), 0.4, kTol);
  const double radius = (speeds.y() + speeds.x()) / (speeds.y() - speeds.x()) * 0.40 / 2.0;
  EXPECT_NEAR(radius, 0.6, kTol);
}

TEST(DiffDriveTwist, NaNInputIsTreatedAsZero) {
  const WheelSpeeds only_turn = wheelSpeedsFromTwist(defaultGeometry(), kNaN, 1.0);
  EXPECT_NEAR(only_turn.x(), -0.2, kTol);
  EXPECT_NEAR(only_turn.y(), 0.2, kTol);
  const WheelSpeeds only_linear = wheelSpeedsFromTwist(defaultGeometry(), 0.3, kNaN);
  EXPECT_NEAR(only_linear.x(), 0.3, kTol);
  EXPECT_NEAR(only_linear.y(), 0.3, kTol);
}

TEST(DiffDriveClamp, KeepsTheRatioWhenScalingDown) {
  const WheelSpeeds clamped = clampWheelSpeeds(WheelSpeeds(0.5, 1.0), 0.8);
  EXPECT_NEAR(clamped.x(), 0.4, kTol);
  EXPECT_NEAR(clamped.y(), 0.8, kTol);
}

TEST(DiffDriveClamp, UsesTheLargestMagnitudeIncludingNegative) {
  const WheelSpeeds clamped = clampWheelSpeeds(WheelSpeeds(-1.2, 0.6), 0.6);
  EXPECT_NEAR(clamped.x(), -0.6, kTol);
  EXPECT_NEAR(clamped.y(), 0.3, kTol);
}

TEST(DiffDriveClamp, LeavesSpeedsWithinTheLimitAlone) {
  const WheelSpeeds clamped = clampWheelSpeeds(WheelSpeeds(-0.3, 0.7), 0.8);
  EXPECT_NEAR(clamped.x(), -0.3, kTol);
  EXPECT_NEAR(clamped.y(), 0.7, kTol);
}

// A limit that is not > 0 is invalid (the parameter table refuses it): it never means "no limit";
// the safe reading is a stop.
TEST(DiffDriveClamp, InvalidMaximumStopsTheWheelsInsteadOfRemovingTheLimit) {
  for (const double limit : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    SCOPED_TRACE(limit);
    const WheelSpeeds clamped = clampWheelSpeeds(WheelSpeeds(5.0, -7.0), limit);
    EXPECT_EQ(clamped.x(), 0.0);
    EXPECT_EQ(clamped.y(), 0.0);
  }
}

TEST(DiffDriveAccel, RampsTowardTheTargetKeepingTheRatio) {
  AccelerationLimiter limiter(1.0);  // 1 m/s^2, 0.1 s steps: at most 0.1 m/s per step
  const WheelSpeeds target(0.5, 1.0);
  for (int step = 1; step <= 10; ++step) {
    const WheelSpeeds out = limiter.step(target, 0.1);
    EXPECT_NEAR(out.y(), 0.1 * step, 1e-9) << "step " << step;
    EXPECT_NEAR(out.x(), 0.5 * out.y(), 1e-9) << "step " << step;
  }
  const WheelSpeeds settled = limiter.step(target, 0.1);
  EXPECT_NEAR(settled.x(), 0.5, kTol);
  EXPECT_NEAR(settled.y(), 1.0, kTol);
  EXPECT_NEAR(limiter.current().y(), 1.0, kTol);
}

TEST(DiffDriveAccel, RampsDownAsWell) {
  AccelerationLimiter limiter(2.0);
  limiter.reset(WheelSpeeds(0.4, 0.8));
  const WheelSpeeds out = limiter.step(WheelSpeeds::Zero(), 0.1);  // at most 0.2 m/s change
  EXPECT_NEAR(out.x(), 0.3, kTol);
  EXPECT_NEAR(out.y(), 0.6, kTol);
}

TEST(DiffDriveAccel, ZeroMeansNoLimit) {
  AccelerationLimiter limiter(0.0);
  const WheelSpeeds out = limiter.step(WheelSpeeds(-3.0, 4.0), 0.02);
  EXPECT_NEAR(out.x(), -3.0, kTol);
  EXPECT_NEAR(out.y(), 4.0, kTol);
}

TEST(DiffDriveAccel, NonPositiveTimeStepChangesNothing) {
  AccelerationLimiter limiter(1.0);
  limiter.reset(WheelSpeeds(0.2, 0.3));
  for (double dt : {0.0, -0.5}) {
    const WheelSpeeds out = limiter.step(WheelSpeeds(1.0, 1.0), dt);
    EXPECT_NEAR(out.x(), 0.2, kTol);
    EXPECT_NEAR(out.y(), 0.3, kTol);
  }
}

TEST(DiffDriveAccel, NaNTargetRampsTowardStop) {
  AccelerationLimiter limiter(1.0);
  limiter.reset(WheelSpeeds(0.5, 0.5));
  const WheelSpeeds out = limiter.step(WheelSpeeds(kNaN, kNaN), 0.1);
  EXPECT_NEAR(out.x(), 0.4, kTol);
  EXPECT_NEAR(out.y(), 0.4, kTol);
}

// --- vendor truncation: int(v * ticks_per_meter / PID_RATE) ----------------------------------

class DiffDriveTruncation : public ::testing::TestWithParam<std::tuple<double, int>> {};

TEST_P(DiffDriveTruncation, ReproducesTheVendorNumbers) {
  const auto [speed, expected_ticks] = GetParam();
  TickQuantizer quantizer(defaultGeometry(), /*dithering=*/false);
  // Same value every period: truncation carries nothing over.
  for (int period = 0; period < 3; ++period) {
    const WheelTicks ticks = quantizer.quantize(WheelSpeeds(speed, -speed));
    EXPECT_EQ(ticks.left, expected_ticks);
    EXPECT_EQ(ticks.right, -expected_ticks);
  }
}

INSTANTIATE_TEST_SUITE_P(
    DiffDriveSpecNumbers, DiffDriveTruncation,
    ::testing::Values(std::make_tuple(0.1, 4), std::make_tuple(0.2, 8), std::make_tuple(1.0, 40),
                      std::make_tuple(-0.15, -6),
                      // the dead band: anything under 1 / 40.7437 = 0.02454 m/s is 0
                      std::make_tuple(0.02, 0), std::make_tuple(0.0245, 0),
                      std::make_tuple(0.0246, 1), std::make_tuple(0.0, 0)));

// --- dithering: error feedback keeps the mean exact -------------------------------------------

class DiffDriveDithering : public ::testing::TestWithParam<double> {};

TEST_P(DiffDriveDithering, MeanOverManyPeriodsEqualsTheExactSpeed) {
  const double speed = GetParam();
  TickQuantizer quantizer(defaultGeometry(), /*dithering=*/true);
  const WheelSpeeds speeds(speed, -speed);
  const Eigen::Vector2d exact = quantizer.exactTicks(speeds);
  constexpr int kPeriods = 1000;
  double left_sum = 0.0;
  double right_sum = 0.0;
  for (int period = 0; period < kPeriods; ++period) {
    const WheelTicks ticks = quantizer.quantize(speeds);
    // Each period sends one of the two integers around the exact value.
    EXPECT_GE(ticks.left, std::floor(exact.x()));
    EXPECT_LE(ticks.left, std::ceil(exact.x()));
    left_sum += ticks.left;
    right_sum += ticks.right;
  }
  EXPECT_NEAR(left_sum / kPeriods, exact.x(), 0.001 * std::abs(exact.x()));
  EXPECT_NEAR(right_sum / kPeriods, exact.y(), 0.001 * std::abs(exact.y()));
}

// 0.02 m/s is 0.815 ticks: truncation would send 0 forever.
INSTANTIATE_TEST_SUITE_P(DiffDriveSpeeds, DiffDriveDithering,
                         ::testing::Values(0.02, -0.02, 0.03, 0.1, -0.15, 0.333, -0.987));

TEST(DiffDriveQuantizer, ExactTicksForTheSpecSpeed) {
  TickQuantizer quantizer(defaultGeometry(), true);
  const Eigen::Vector2d exact = quantizer.exactTicks(WheelSpeeds(0.02, 0.1));
  EXPECT_NEAR(exact.x(), 0.815, 0.001);
  EXPECT_NEAR(exact.y(), 4.074, 0.001);
}

TEST(DiffDriveQuantizer, CarriesTheRemainderToTheNextPeriod) {
  // 0.012 m/s = 0.489 ticks: 0 now, and the carried 0.489 makes the next period 1.
  TickQuantizer quantizer(defaultGeometry(), true);
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.012, 0.012)), (WheelTicks{0, 0}));
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.012, 0.012)), (WheelTicks{1, 1}));
}

TEST(DiffDriveQuantizer, ResetForgetsTheRemainder) {
  TickQuantizer quantizer(defaultGeometry(), true);
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.012, 0.012)), (WheelTicks{0, 0}));
  quantizer.reset();
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.012, 0.012)), (WheelTicks{0, 0}));
}

TEST(DiffDriveQuantizer, SaturatesAtInt16Limits) {
  for (bool dithering : {false, true}) {
    TickQuantizer quantizer(defaultGeometry(), dithering);
    EXPECT_EQ(quantizer.quantize(WheelSpeeds(1000.0, -1000.0)), (WheelTicks{32767, -32768}))
        << "dithering " << dithering;
  }
}

TEST(DiffDriveQuantizer, InfiniteSpeedSendsZero) {
  // Not a number a motor should chase: treated as "stop" like NaN.
  const double inf = std::numeric_limits<double>::infinity();
  for (bool dithering : {false, true}) {
    TickQuantizer quantizer(defaultGeometry(), dithering);
    EXPECT_EQ(quantizer.quantize(WheelSpeeds(-inf, inf)), (WheelTicks{0, 0}))
        << "dithering " << dithering;
  }
}

TEST(DiffDriveQuantizer, ZeroCommandGivesZeroTicksWhateverTheRemainder) {
  // 0.5 / 40.7437 m/s leaves exactly +0.5 tick to carry at first; round(0.5) = 1 is sent and -0.5
  // carried. A zero command afterwards must send 0, not round(-0.5) = -1 then +1, -1, ...
  TickQuantizer quantizer(defaultGeometry(), true);
  const double half_tick = 0.5 / defaultGeometry().ticksPerPeriodPerMps();
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(half_tick, -half_tick)), (WheelTicks{1, -1}));
  for (int period = 0; period < 10; ++period) {
    EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.0, 0.0)), (WheelTicks{0, 0})) << "period " << period;
  }
  // The stop forgot the debt: the next small speed starts afresh (0.012 m/s is 0.49 tick: 0).
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.012, 0.012)), (WheelTicks{0, 0}));
}

TEST(DiffDriveClamp, InfiniteSpeedIsAStopNotNaN) {
  const double inf = std::numeric_limits<double>::infinity();
  const WheelSpeeds clamped = clampWheelSpeeds(WheelSpeeds(inf, 0.5), 1.0);
  EXPECT_TRUE(clamped.allFinite());
  EXPECT_NEAR(clamped.x(), 0.0, kTol);
  EXPECT_NEAR(clamped.y(), 0.5, kTol);
}

TEST(DiffDriveQuantizer, SaturationDoesNotWindUpTheRemainder) {
  TickQuantizer quantizer(defaultGeometry(), true);
  for (int period = 0; period < 100; ++period) quantizer.quantize(WheelSpeeds(1000.0, -1000.0));
  // 0.1 m/s is 4.07 ticks: a wound-up remainder would send something far from 4.
  EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.1, 0.1)), (WheelTicks{4, 4}));
}

TEST(DiffDriveQuantizer, NaNSpeedSendsZeroAndDoesNotPoisonTheRemainder) {
  for (bool dithering : {false, true}) {
    TickQuantizer quantizer(defaultGeometry(), dithering);
    EXPECT_EQ(quantizer.quantize(WheelSpeeds(kNaN, kNaN)), (WheelTicks{0, 0}));
    EXPECT_EQ(quantizer.quantize(WheelSpeeds(0.1, -0.15)), (WheelTicks{4, -6}));
  }
}

}  // namespace
}  // namespace serial_robot_driver::kinematics
