// The simulated devices alone (base, body, servo bus), driven with explicit time points: no
// threads, no pty.
#include <gtest/gtest.h>

#include "support/sim_host.h"

namespace serial_robot_driver::sim {
namespace {

using namespace sim_test;  // NOLINT: the shared fixture

// --- devices alone, on explicit time ---------------------------------------------------------

TEST(RobotSimBaseDevice, IntegratesOncePerPidPeriodAndTimesOut) {
  const TimePoint t0{};
  devices::base::sim::BaseSim base(devices::base::sim::BaseSimConfig{}, t0);
  Outbox out;
  base.handleFrame(kBoth4Seq0.data(), kBoth4Seq0.size(), t0, &out);
  base.tick(t0 + milliseconds(105), &out);  // 5 periods of 20 ms
  EXPECT_EQ(base.stats().left_ticks, 20);
  EXPECT_EQ(base.stats().right_ticks, 20);
  EXPECT_TRUE(out.empty());

  base.tick(t0 + milliseconds(1002), &out);  // more than 1 s of silence
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].bytes, kErrorStatusSeq0);
  EXPECT_TRUE(base.stats().in_error);
  EXPECT_EQ(base.stats().last_left_speed, 0);  // a base that lost its host stops
  const int64_t ticks_at_error = base.stats().left_ticks;
  base.tick(t0 + milliseconds(2003), &out);  // repeated once per second while in error
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(base.stats().left_ticks, ticks_at_error);
}

TEST(RobotSimBaseDevice, YawRateFollowsTheWheelDifference) {
  const TimePoint t0{};
  devices::base::sim::BaseSim base(devices::base::sim::BaseSimConfig{}, t0);
  Outbox out;
  // left 0, right 4 ticks per period: 4 * 50 / 2037.18 m/s on the right wheel, 0.40 m apart.
  const Bytes right4 = {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x00,
                        0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF3};
  base.handleFrame(right4.data(), right4.size(), t0, &out);
  EXPECT_NEAR(base.yawRate(), (4 * 50 / (1600 / (0.25 * M_PI))) / 0.40, 1e-9);
  EXPECT_GT(base.yawRate(), 0.0);  // right wheel faster: counter-clockwise
}

TEST(RobotSimBaseDevice, TurnSlipTurnsTheChassisLessThanItsWheelsCommand) {
  const TimePoint t0{};
  devices::base::sim::BaseSimConfig config;
  config.turn_slip = 0.3;
  devices::base::sim::BaseSim base(config, t0);
  Outbox out;
  const Bytes right4 = {0x55, 0xAA, 0x09, 0x00, 0x01, 0x00, 0x00,
                        0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0xF3};
  base.handleFrame(right4.data(), right4.size(), t0, &out);
  base.tick(t0 + milliseconds(105), &out);  // 5 PID periods
  // The encoders count every tick; the chassis turns by 70 % of what the ticks command:
  // 5 periods * 4 ticks * (0.25 pi / 1600) m / 0.40 m = 0.0245437 rad commanded.
  EXPECT_EQ(base.stats().right_ticks, 20);
  EXPECT_NEAR(base.stats().yaw_rad, 0.7 * 0.0245437, 1e-6);
  EXPECT_NEAR(base.yawRate(), 0.7 * (4 * 50 / (1600 / (0.25 * M_PI))) / 0.40, 1e-9);
}

TEST(RobotSimBodyDevice, ImuReportsTheChassisHeadingAndYawRate) {
  const TimePoint t0{};
  devices::body::sim::BodySimConfig config;
  config.telemetry_rate_hz = 50;
  devices::body::sim::BodySim body(config, t0);
  Outbox out;
  body.tick(t0 + milliseconds(20), ChassisMotion{1.0, 0.5}, &out);
  ASSERT_EQ(out.size(), 1u);
  const auto telemetry =
      devices::body::decodeTelemetry(out[0].bytes.data(), out[0].bytes.size(), 2);
  ASSERT_TRUE(telemetry.ok());
  // 1 rad at 180 deg / 32768 per LSB: 10430.4 LSB; 0.5 rad/s at 2000 deg/s / 32768: 469.4 LSB.
  EXPECT_EQ(telemetry->imu[devices::body::kYaw], 10430);
  EXPECT_EQ(telemetry->imu[devices::body::kGyroZ], 469);
  // A heading beyond pi is reported wrapped, as an attitude module does: 4 rad = 4 - 2 pi.
  out.clear();
  body.tick(t0 + milliseconds(40), ChassisMotion{4.0, 0.0}, &out);
  ASSERT_EQ(out.size(), 1u);
  const auto wrapped = devices::body::decodeTelemetry(out[0].bytes.data(), out[0].bytes.size(), 2);
  ASSERT_TRUE(wrapped.ok());
  EXPECT_EQ(wrapped->imu[devices::body::kYaw], -23814);  // -2.2832 rad * 32768 / pi
}

TEST(RobotSimBodyDevice, GyroBiasIsAddedToEachGyroAxis) {
  const TimePoint t0{};
  devices::body::sim::BodySimConfig config;
  config.telemetry_rate_hz = 50;
  config.gyro_bias = {0.02, -0.015, 0.03};  // rad/s, as --gyro-bias 0.02,-0.015,0.03
  devices::body::sim::BodySim body(config, t0);
  Outbox out;
  body.tick(t0 + milliseconds(20), ChassisMotion{0.0, 0.5}, &out);
  ASSERT_EQ(out.size(), 1u);
  const auto telemetry =
      devices::body::decodeTelemetry(out[0].bytes.data(), out[0].bytes.size(), 2);
  ASSERT_TRUE(telemetry.ok());
  // 938.734 LSB per rad/s (2000 deg/s / 32768): 18.77, -14.08 and (0.5 + 0.03) * 938.734 = 497.5.
  EXPECT_EQ(telemetry->imu[devices::body::kGyroX], 19);
  EXPECT_EQ(telemetry->imu[devices::body::kGyroY], -14);
  EXPECT_EQ(telemetry->imu[devices::body::kGyroZ], 498);
  EXPECT_EQ(telemetry->imu[devices::body::kAccelX], 0) << "the accelerometer is left alone";
  EXPECT_EQ(telemetry->imu[devices::body::kRoll], 0) << "and so are the angles";

  const char* args[] = {"robot_sim", "--gyro-bias", "0.02,-0.015,0.03"};
  CommandLine line = parseCommandLine(3, args);
  ASSERT_TRUE(line.error.empty()) << line.error;
  EXPECT_EQ(devices::body::sim::bodyConfig(line.options).gyro_bias,
            (std::array<double, 3>{0.02, -0.015, 0.03}));
  for (const char* bad : {"0.02,0.01", "1,2,3,4", "a,b,c", "0.1,,0.2", "1,2,nan"}) {
    EXPECT_FALSE(devices::body::sim::parseGyroBias(bad).has_value()) << bad;
  }
  EXPECT_NE(usage().find("--gyro-bias X,Y,Z"), std::string::npos);
}

TEST(RobotSimBodyDevice, ServoMovesAtTheBoundedSpeed) {
  const TimePoint t0{};
  devices::body::sim::BodySimConfig config;
  config.servo_ids = {2, 3};
  config.servo_speed = 1000;
  config.telemetry_rate_hz = 0;
  devices::body::sim::BodySim body(config, t0);
  body.handleSyncWrite(kSyncWrite2And3.data(), kSyncWrite2And3.size());
  Outbox out;
  body.tick(t0 + milliseconds(500), ChassisMotion{}, &out);
  EXPECT_TRUE(out.empty());  // telemetry off
  EXPECT_NEAR(body.stats().servos[1].position, 2048 - 500, 1e-6);
  EXPECT_EQ(body.stats().servos[1].speed, -1000);
  EXPECT_EQ(body.stats().servos[0].speed, 0);
  body.tick(t0 + milliseconds(2000), ChassisMotion{}, &out);
  EXPECT_NEAR(body.stats().servos[1].position, 1024, 1e-6);
}

// --- ServoBusSim on its own, in simulated time (no threads, no pty) --------------------------

class ServoBusSimMotion : public ::testing::Test {
 protected:
  ServoBusSimMotion() : start_(TimePoint() + std::chrono::hours(1)), sim_(config(), start_) {}
  static devices::servo_bus::sim::ServoBusSimConfig config() {
    devices::servo_bus::sim::ServoBusSimConfig c;
    c.servo_ids = {0, 1};
    c.answer_latency_s = 0.001;
    return c;
  }
  void send(const Bytes& request, double at_s) {
    sim_.handleRequest(request.data(), request.size(), start_ + fromSeconds(at_s));
  }
  double angleAt(double at_s, uint8_t id = 1) {
    Outbox out;
    sim_.tick(start_ + fromSeconds(at_s), &out);
    for (const devices::servo_bus::sim::BusServoSnapshot& servo : sim_.stats().servos) {
      if (servo.id == id) return servo.angle_deg;
    }
    ADD_FAILURE() << "no servo " << int(id);
    return 0.0;
  }
  std::vector<Bytes> answersUntil(double at_s) {
    Outbox out;
    sim_.tick(start_ + fromSeconds(at_s), &out);
    std::vector<Bytes> frames;
    for (Outgoing& frame : out) frames.push_back(std::move(frame.bytes));
    return frames;
  }
  TimePoint start_;
  devices::servo_bus::sim::ServoBusSim sim_;
};

TEST_F(ServoBusSimMotion, MoveByIntervalRunsATrapezoidInTheInterval) {
  send(kMoveByInterval1To90, 0.0);  // 90 deg in 1000 ms, 100 ms ramps: cruise 100 deg/s
  EXPECT_NEAR(angleAt(0.05), 0.5 * 100.0 / 0.1 * 0.05 * 0.05, 1e-6);  // accelerating
  EXPECT_NEAR(angleAt(0.5), 45.0, 1e-6);                              // symmetric midpoint
  EXPECT_LT(angleAt(0.95), 90.0);                                     // still decelerating
  EXPECT_DOUBLE_EQ(angleAt(1.0), 90.0);
  EXPECT_TRUE(answersUntil(1.1).empty());  // response_switch 0: no answer to a move
}

TEST_F(ServoBusSimMotion, MoveByVelocityTakesDistanceOverSpeedPlusTheRamps) {
  send(kMoveByVelocity1ToMinus90, 0.0);  // -90 deg at 360 deg/s, 100 ms ramps: 0.35 s
  EXPECT_NEAR(angleAt(0.175), -45.0, 1e-6);
  EXPECT_GT(angleAt(0.34), -90.0);
  EXPECT_DOUBLE_EQ(angleAt(0.36), -90.0);
}

TEST_F(ServoBusSimMotion, MultiTurnMoveKeepsTheTurnsAndAnswersCmd16) {
  send(kMultiTurnMove1To720, 0.0);  // 720 deg in 2000 ms, no ramps
  EXPECT_NEAR(angleAt(1.0), 360.0, 1e-6);
  EXPECT_DOUBLE_EQ(angleAt(2.0), 720.0);
  send(kReadMultiTurn1, 2.0);
  EXPECT_EQ(answersUntil(2.01), std::vector<Bytes>{kReadMultiTurn1Reply720});
  // READ_ANGLE folds the same angle into one turn: 0.0 deg (05+1C+0A+03+01 = 2F).
  send({0x12, 0x4C, 0x0A, 0x01, 0x01, 0x6A}, 2.02);
  const Bytes folded_reply = {0x05, 0x1C, 0x0A, 0x03, 0x01, 0x00, 0x00, 0x2F};
  EXPECT_EQ(answersUntil(2.03), std::vector<Bytes>{folded_reply});
}

TEST_F(ServoBusSimMotion, MultiTurnMovesByIntervalAndVelocityReachTheirTargets) {
  send(kMultiTurnMoveByInterval1ToMinus360, 0.0);  // 1000 ms, 200 ms ramps
  EXPECT_NEAR(angleAt(0.5), -180.0, 1e-6);
  EXPECT_DOUBLE_EQ(angleAt(1.0), -360.0);
  send(kMultiTurnMoveByVelocity1To3600, 1.0);  // 3960 deg at 360 deg/s + 0.1 s of ramps = 11.1 s
  EXPECT_LT(angleAt(12.0), 3600.0);
  EXPECT_DOUBLE_EQ(angleAt(12.2), 3600.0);
}

TEST_F(ServoBusSimMotion, ResetAnswersFromTheFactoryId) {
  // RESET_USER_DATA id 1: 5E+02+01+01 = 62.
  send({0x12, 0x4C, 0x02, 0x01, 0x01, 0x62}, 0.0);
  EXPECT_EQ(answersUntil(0.01), std::vector<Bytes>{kResetUserDataOkFromId0});
}

TEST_F(ServoBusSimMotion, MoveWithAWrongLengthIsMalformed) {
  Bytes short_move(kMoveByInterval1To90.begin(), kMoveByInterval1To90.end());
  // Drop the power field: N = 9, SUM without the two zero bytes is unchanged, minus 2 for N.
  short_move.erase(short_move.end() - 3, short_move.end() - 1);
  short_move[3] = 0x09;
  short_move.back() = static_cast<uint8_t>(short_move.back() - 2);
  send(short_move, 0.0);
  EXPECT_EQ(sim_.stats().malformed, 1u);
  EXPECT_DOUBLE_EQ(angleAt(2.0), 0.0);
}

}  // namespace
}  // namespace serial_robot_driver::sim
