// ServoBusClient's operations against a fake bus (servo_bus_client_fixture.h): parameters read
// and written back, angles, motions, the user block, servo_id changes, resets, moves and scans,
// each with the frames on the wire.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "support/servo_bus_client_fixture.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using protocol::FrameFamily;
using namespace golden::servo;  // NOLINT: the frames shared with the rostest

TEST_F(ServoBusClientTest, ReadUnsignedParameterInItsUnit) {
  bus_.answer(kReadVoltage3, {kReadVoltage3Reply});
  ServoParamValue value;
  const ServoStatus status = client_.readParam(3, "voltage", &value);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(value.value, 7400);
  EXPECT_EQ(value.unit, "mV");
  EXPECT_EQ(value.data_id, 1);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadVoltage3});
}

TEST_F(ServoBusClientTest, ReadSignedParameterByDataIdText) {
  bus_.answer(kReadLimitLow3, {kReadLimitLow3Reply});
  ServoParamValue value;
  const ServoStatus status = client_.readParam(3, "52", &value);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(value.value, -900);
  EXPECT_EQ(value.unit, "0.1deg");
  EXPECT_EQ(value.name, "angle_limit_low");
}

TEST_F(ServoBusClientTest, ReadAnswerAboutAnotherParameterIsIgnored) {
  bus_.answer(kReadLimitLow3, {kReadVoltage3Reply, kReadLimitLow3Reply});
  ServoParamValue value;
  ASSERT_TRUE(client_.readParam(3, "angle_limit_low", &value).ok());
  EXPECT_EQ(value.value, -900);
  EXPECT_EQ(client_.stats().mismatched, 1u);
}

TEST_F(ServoBusClientTest, ReadAngleInDegrees) {
  bus_.answer(kReadAngle0, {kReadAngle0Reply902});
  double angle = 0.0;
  const ServoStatus status = client_.readAngle(0, &angle);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_DOUBLE_EQ(angle, 90.2);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadAngle0});
}

TEST_F(ServoBusClientTest, WriteIsReadBack) {
  bus_.answer(kWriteSoftStart3, {kWriteSoftStart3Ok});
  bus_.answer(kReadSoftStart3, {kReadSoftStart3Reply300});
  const ServoStatus status = client_.writeParam(3, "soft_start_time", 300);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kWriteSoftStart3, kReadSoftStart3}));
}

TEST_F(ServoBusClientTest, WriteResultZeroIsAFailureWithoutReadBack) {
  bus_.answer(kWriteSoftStart3, {kWriteSoftStart3Failed});
  const ServoStatus status = client_.writeParam(3, "50", 300);
  EXPECT_EQ(status.error, ServoError::kRefused);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kWriteSoftStart3});
}

TEST_F(ServoBusClientTest, WriteWithDifferentReadBackFails) {
  bus_.answer(kWriteSoftStart3, {kWriteSoftStart3Ok});
  bus_.answer(kReadSoftStart3, {kReadSoftStart3Reply200});
  const ServoStatus status = client_.writeParam(3, "soft_start_time", 300);
  EXPECT_EQ(status.error, ServoError::kReadBackMismatch);
  EXPECT_NE(status.message.find("reads back 200"), std::string::npos) << status.message;
}

TEST_F(ServoBusClientTest, RotateSendsGoldenFrameWithoutWaiting) {
  RotateRequest request;
  request.id = 2;
  request.angle_deg = 90.0;
  request.interval_ms = 500;
  const ServoStatus status = client_.rotate(request);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kRotate2To90In500});
  EXPECT_EQ(client_.stats().commands, 1u);
  EXPECT_EQ(client_.stats().transactions, 0u);
}

TEST_F(ServoBusClientTest, RotateWithWaitGetsTheCompletionAnswer) {
  bus_.answer(kRotate2To90In500, {kRotate2Done});
  RotateRequest request;
  request.id = 2;
  request.angle_deg = 90.0;
  request.interval_ms = 500;
  request.wait = true;
  const ServoStatus status = client_.rotate(request);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(client_.stats().transactions, 1u);
}

TEST_F(ServoBusClientTest, MotionWaitTimesOutWithoutResending) {
  const ServoStatus status = client_.damping(0, 500, /*wait=*/true);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_NE(status.message.find("response_switch"), std::string::npos) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kDamping0At500});
}

TEST_F(ServoBusClientTest, SpinAndDampingSendGoldenFrames) {
  SpinRequest spin;
  spin.id = 0;
  spin.mode = 1;
  spin.speed_dps = 100;
  ASSERT_TRUE(client_.spin(spin).ok());
  spin.clockwise = true;
  spin.mode = 2;
  spin.value = 5;
  ASSERT_TRUE(client_.spin(spin).ok());
  ASSERT_TRUE(client_.damping(0, 500, false).ok());
  EXPECT_EQ(bus_.written,
            (std::vector<Bytes>{kSpin0CcwContinuous, kSpin0Cw5Turns, kDamping0At500}));
}

TEST_F(ServoBusClientTest, BroadcastMotionWithoutWaitIsAllowed) {
  RotateRequest rotate;
  rotate.id = 255;
  EXPECT_TRUE(client_.rotate(rotate).ok());
  SpinRequest spin;
  spin.id = 255;
  EXPECT_TRUE(client_.spin(spin).ok());
  EXPECT_TRUE(client_.damping(255, 0, false).ok());
  EXPECT_EQ(bus_.written.size(), 3u);
}

TEST_F(ServoBusClientTest, ReadAllDecodesTheUserBlock) {
  bus_.answer(kReadBatch3, {kReadBatch3Reply});
  std::vector<ServoParamValue> values;
  const ServoStatus status = client_.readAll(3, &values);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadBatch3});

  const std::vector<std::pair<std::string, int64_t>> expected = {{"reserved_32", 0},
                                                                 {"response_switch", 0},
                                                                 {"servo_id", 3},
                                                                 {"reserved_35", 0},
                                                                 {"baudrate", 5},
                                                                 {"stall_protect_mode", 1},
                                                                 {"stall_power_limit", 4000},
                                                                 {"over_volt_low", 4500},
                                                                 {"over_volt_high", 14000},
                                                                 {"over_temperature", 80},
                                                                 {"over_power", 12000},
                                                                 {"over_current", 3000},
                                                                 {"accel_switch", 1},
                                                                 {"reserved_45", 0},
                                                                 {"po_lock_switch", 0},
                                                                 {"wb_lock_switch", 1},
                                                                 {"angle_limit_switch", 1},
                                                                 {"soft_start_switch", 0},
                                                                 {"soft_start_time", 300},
                                                                 {"angle_limit_high", 1800},
                                                                 {"angle_limit_low", -1800},
                                                                 {"angle_mid_offset", -5}};
  ASSERT_EQ(values.size(), 22u);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(values[i].name, expected[i].first) << i;
    EXPECT_EQ(values[i].value, expected[i].second) << values[i].name;
    EXPECT_EQ(values[i].data_id, 32 + i);
  }
  EXPECT_EQ(values[6].unit, "mW");
  EXPECT_EQ(values[20].unit, "0.1deg");
}

TEST_F(ServoBusClientArmedTest, ServoIdChangePingsTheNewIdThenReadsBackThere) {
  bus_.answer(kWriteServoId3To5, {kWriteServoId3To5Ok});
  bus_.answer(kReadServoId5, {kReadServoId5Reply});
  const ServoStatus status = client_.writeParam(3, "servo_id", 5);
  EXPECT_TRUE(status.ok()) << status.message;
  // PING 5 twice (nobody there), then the write, then the read-back at the new id.
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kPing5, kPing5, kWriteServoId3To5, kReadServoId5}));
}

TEST_F(ServoBusClientArmedTest, ServoIdChangeRefusedWhenTheNewIdAnswers) {
  bus_.answer(kPing5, {kPing5Reply});
  const ServoStatus status = client_.writeParam(3, "servo_id", 5);
  EXPECT_EQ(status.error, ServoError::kIdInUse);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kPing5});
}

TEST_F(ServoBusClientArmedTest, ResetUserData) {
  bus_.answer(kResetUserData3, {kResetUserData3Ok});
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kResetUserData3});
}

TEST_F(ServoBusClientArmedTest, ResetUserDataAnsweredFromTheDefaultId) {
  bus_.answer(kResetUserData3, {kResetUserDataOkFromId0});
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kResetUserData3});
}

TEST_F(ServoBusClientArmedTest, SilentResetSucceedsWhenIdZeroAnswersPing) {
  bus_.answer(kPing0, {kPing0Reply});
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_NE(status.message.find("id 0"), std::string::npos) << status.message;
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kResetUserData3, kPing0}));
}

TEST_F(ServoBusClientArmedTest, SilentResetWithNobodyAtIdZeroFails) {
  const ServoStatus status = client_.resetUserData(3);
  EXPECT_EQ(status.error, ServoError::kTimeout) << status.message;
  // retries = 1: two rounds of reset + PING 0.
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kResetUserData3, kPing0, kResetUserData3, kPing0}));
}

TEST_F(ServoBusClientTest, MoveChoosesTheCommandFromTheRequest) {
  MoveRequest plain;
  plain.id = 2;
  plain.angle_deg = 90.0;
  plain.interval_ms = 500;
  EXPECT_TRUE(client_.move(plain).ok());

  MoveRequest ramps;
  ramps.id = 1;
  ramps.angle_deg = 90.0;
  ramps.interval_ms = 1000;
  ramps.accel_ms = 100;
  ramps.decel_ms = 100;
  EXPECT_TRUE(client_.move(ramps).ok());

  MoveRequest velocity;
  velocity.id = 1;
  velocity.angle_deg = -90.0;
  velocity.velocity_dps = 360.0;
  velocity.accel_ms = 100;
  velocity.decel_ms = 100;
  EXPECT_TRUE(client_.move(velocity).ok());

  MoveRequest multi;
  multi.id = 1;
  multi.multi_turn = true;
  multi.angle_deg = 720.0;
  multi.interval_ms = 2000;
  EXPECT_TRUE(client_.move(multi).ok());

  MoveRequest multi_ramps;
  multi_ramps.id = 1;
  multi_ramps.multi_turn = true;
  multi_ramps.angle_deg = -360.0;
  multi_ramps.interval_ms = 1000;
  multi_ramps.accel_ms = 200;
  multi_ramps.decel_ms = 200;
  EXPECT_TRUE(client_.move(multi_ramps).ok());

  MoveRequest multi_velocity;
  multi_velocity.id = 1;
  multi_velocity.multi_turn = true;
  multi_velocity.angle_deg = 3600.0;
  multi_velocity.velocity_dps = 360.0;
  multi_velocity.accel_ms = 100;
  multi_velocity.decel_ms = 100;
  EXPECT_TRUE(client_.move(multi_velocity).ok());

  EXPECT_EQ(bus_.written,
            (std::vector<Bytes>{kRotate2To90In500, kMoveByInterval1To90, kMoveByVelocity1ToMinus90,
                                kMultiTurnMove1To720, kMultiTurnMoveByInterval1ToMinus360,
                                kMultiTurnMoveByVelocity1To3600}));
  EXPECT_EQ(client_.stats().commands, 6u);
}

TEST_F(ServoBusClientTest, MoveByVelocityWithoutRampsSendsTheShortestRamps) {
  MoveRequest velocity;
  velocity.id = 1;
  velocity.angle_deg = -90.0;
  velocity.velocity_dps = 360.0;
  ASSERT_TRUE(client_.move(velocity).ok());
  // CMD 12 id 1, -900 (7C FC), 3600 (10 0E), accel 20 (14 00), decel 20, power 0.
  // 5E+0C+0B+01+7C+FC+10+0E+14+14 = 0x234 -> 34
  const Bytes expected = {0x12, 0x4C, 0x0C, 0x0B, 0x01, 0x7C, 0xFC, 0x10,
                          0x0E, 0x14, 0x00, 0x14, 0x00, 0x00, 0x00, 0x34};
  EXPECT_EQ(bus_.written, std::vector<Bytes>{expected});
}

TEST_F(ServoBusClientTest, ReadMultiTurnAngle) {
  bus_.answer(kReadMultiTurn1, {kReadMultiTurn1Reply720});
  MultiTurnReading reading;
  const ServoStatus status = client_.readMultiTurnAngle(1, &reading);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_DOUBLE_EQ(reading.angle_deg, 720.0);
  EXPECT_EQ(reading.turns, 2);
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kReadMultiTurn1});
}

TEST_F(ServoBusClientTest, ScanListsTheIdsThatAnswerWithOneAttemptEach) {
  bus_.answer(kPing3, {kPing3Reply});
  bus_.answer(kPing5, {kPing5Reply});
  std::vector<uint8_t> ids;
  const ServoStatus status = client_.scan(3, 7, &ids);
  ASSERT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(ids, (std::vector<uint8_t>{3, 5}));
  // 3 silent ids (4, 6, 7) cost one PING each: no retries.
  ASSERT_EQ(bus_.written.size(), 5u);
  EXPECT_EQ(bus_.written.front(), kPing3);
  EXPECT_EQ(bus_.written.back(), kPing7);
  EXPECT_EQ(client_.stats().retries, 0u);
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
