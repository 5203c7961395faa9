// The bus servo command table and the typed requests/answers built on it: the golden frames of
// test/support (written by hand from docs/protocols.md, section 3) decode to what they say, every
// golden request fits its row of the table, and typed answers re-encode to the golden bytes.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "serial_robot_driver/protocol/servo_bus_codec.h"
#include "serial_robot_driver/protocol/servo_commands.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::protocol::servo {
namespace {

using Bytes = std::vector<uint8_t>;
using namespace golden::servo;  // NOLINT: the shared golden frames

Packet request(const Bytes& frame) {
  const Decoded<Packet> packet = decodeRequest(frame.data(), frame.size());
  EXPECT_TRUE(packet.ok());
  return packet.ok() ? *packet : Packet{};
}

Packet response(const Bytes& frame) {
  const Decoded<Packet> packet = decodeResponse(frame.data(), frame.size());
  EXPECT_TRUE(packet.ok());
  return packet.ok() ? *packet : Packet{};
}

Bytes contentOf(const Bytes& frame) { return Bytes(frame.begin() + 4, frame.end() - 1); }

TEST(ServoCommandTable, HasOneRowPerCommandInCmdOrder) {
  ASSERT_EQ(commandTable().size(), static_cast<std::size_t>(kMaxCommand));
  for (uint8_t cmd = kMinCommand; cmd <= kMaxCommand; ++cmd) {
    EXPECT_EQ(static_cast<uint8_t>(commandInfo(static_cast<Command>(cmd)).cmd), cmd);
  }
  EXPECT_STREQ(commandInfo(Command::kReadAngle).name, "READ_ANGLE");
  EXPECT_STREQ(commandInfo(Command::kMoveByVelocity).name, "MOVE_BY_VELOCITY (CMD 12)");
}

TEST(ServoCommandTable, MotionsAnswerOnlyWithResponseSwitch) {
  for (Command cmd : {Command::kSpin, Command::kRotate, Command::kDamping, Command::kMoveByInterval,
                      Command::kMultiTurnMoveByVelocity}) {
    EXPECT_EQ(commandInfo(cmd).answers, Answers::kWhenResponseSwitch) << commandInfo(cmd).name;
  }
  for (Command cmd : {Command::kPing, Command::kReadData, Command::kWriteData, Command::kReadAngle,
                      Command::kReadMultiTurnAngle}) {
    EXPECT_EQ(commandInfo(cmd).answers, Answers::kAlways) << commandInfo(cmd).name;
  }
}

TEST(ServoCommandTable, EveryGoldenRequestFitsItsRow) {
  for (const Bytes* frame :
       {&kPing3, &kReadAngle0, &kReadVoltage3, &kWriteSoftStart3, &kWriteServoId3To5,
        &kResetUserData3, &kRotate2To90In500, &kDamping0At500, &kReadBatch3, &kSpin0Cw5Turns,
        &kMoveByInterval1To90, &kMoveByVelocity1ToMinus90, &kMultiTurnMove1To720,
        &kMultiTurnMoveByInterval1ToMinus360, &kMultiTurnMoveByVelocity1To3600, &kReadMultiTurn1}) {
    const Packet packet = request(*frame);
    const CommandInfo& info = commandInfo(static_cast<Command>(packet.cmd));
    EXPECT_TRUE(info.request.fits(packet.content_size)) << info.name;
  }
}

TEST(ServoCommandTable, EveryGoldenAnswerFitsItsRowAndItsResultByteSaysOk) {
  for (const Bytes* frame :
       {&kPing3Reply, &kReadAngle0Reply902, &kReadVoltage3Reply, &kWriteSoftStart3Ok,
        &kResetUserData3Ok, &kReadBatch3Reply, &kRotate2Done, &kReadMultiTurn1Reply720}) {
    const Packet packet = response(*frame);
    const CommandInfo& info = commandInfo(static_cast<Command>(packet.cmd));
    EXPECT_TRUE(info.answer.fits(packet.content_size)) << info.name;
    if (info.result_index != kNoResult) {
      EXPECT_EQ(packet.content[info.result_index], 1);
    }
  }
}

TEST(ServoTypedAnswers, ReadAngleAnswerIs90Point2DegreesAndReencodes) {
  const Decoded<AngleAnswer> angle = decodeAngleAnswer(response(kReadAngle0Reply902));
  ASSERT_TRUE(angle.ok());
  EXPECT_EQ(angle->id, 0);
  EXPECT_EQ(angle->angle_decidegrees, 902);
  EXPECT_EQ(angleAnswerContent(*angle), contentOf(kReadAngle0Reply902));
  EXPECT_FALSE(decodeAngleAnswer(response(kPing3Reply)).ok());
}

TEST(ServoTypedAnswers, ReadDataAnswerFollowsTheParameterType) {
  const ParamInfo* voltage = findParam("voltage");
  const ParamInfo* limit_low = findParam("angle_limit_low");
  ASSERT_NE(voltage, nullptr);
  ASSERT_NE(limit_low, nullptr);
  const Decoded<int64_t> mv = decodeReadDataAnswer(response(kReadVoltage3Reply), *voltage);
  ASSERT_TRUE(mv.ok());
  EXPECT_EQ(*mv, 7400);
  EXPECT_EQ(readDataAnswerContent(3, *voltage, 7400), contentOf(kReadVoltage3Reply));
  const Decoded<int64_t> low = decodeReadDataAnswer(response(kReadLimitLow3Reply), *limit_low);
  ASSERT_TRUE(low.ok());
  EXPECT_EQ(*low, -900);
  EXPECT_EQ(readDataAnswerContent(3, *limit_low, -900), contentOf(kReadLimitLow3Reply));
}

TEST(ServoTypedRequests, MovesDecodeToWhatTheirGoldenBytesSay) {
  const Decoded<MoveCommand> rotate = decodeMove(request(kRotate2To90In500));
  ASSERT_TRUE(rotate.ok());
  EXPECT_EQ(rotate->cmd, Command::kRotate);
  EXPECT_EQ(rotate->id, 2);
  EXPECT_EQ(rotate->angle_decidegrees, 900);
  EXPECT_EQ(rotate->interval_ms, 500u);
  EXPECT_EQ(rotate->ramps.power_mw, 0);

  const Decoded<MoveCommand> by_velocity = decodeMove(request(kMoveByVelocity1ToMinus90));
  ASSERT_TRUE(by_velocity.ok());
  EXPECT_EQ(by_velocity->angle_decidegrees, -900);
  EXPECT_EQ(by_velocity->velocity_decidegrees_per_s, 3600);
  EXPECT_EQ(by_velocity->ramps.accel_ms, 100);
  EXPECT_EQ(by_velocity->ramps.decel_ms, 100);

  const Decoded<MoveCommand> multi = decodeMove(request(kMultiTurnMoveByInterval1ToMinus360));
  ASSERT_TRUE(multi.ok());
  EXPECT_EQ(multi->angle_decidegrees, -3600);
  EXPECT_EQ(multi->interval_ms, 1000u);
  EXPECT_EQ(multi->ramps.accel_ms, 200);
  EXPECT_TRUE(isMultiTurn(multi->cmd));
  EXPECT_FALSE(isByVelocity(multi->cmd));

  const Decoded<MoveCommand> plain = decodeMove(request(kMultiTurnMove1To720));
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->angle_decidegrees, 7200);
  EXPECT_EQ(plain->interval_ms, 2000u);
  EXPECT_FALSE(hasRamps(plain->cmd));

  const Decoded<MoveCommand> turns = decodeMove(request(kMultiTurnMoveByVelocity1To3600));
  ASSERT_TRUE(turns.ok());
  EXPECT_EQ(turns->angle_decidegrees, 36000);
  EXPECT_EQ(turns->velocity_decidegrees_per_s, 3600);
}

TEST(ServoTypedRequests, NotAMoveOrWrongSizeIsRefused) {
  EXPECT_EQ(decodeMove(request(kPing3)).error(), DecodeError::kUnknownCommand);
  Packet short_rotate = request(kRotate2To90In500);
  short_rotate.content_size = 6;
  EXPECT_EQ(decodeMove(short_rotate).error(), DecodeError::kBadLength);
}

TEST(ServoTypedRequests, SpinDecodesDirectionModeSpeedAndValue) {
  const Decoded<SpinCommand> spin = decodeSpin(request(kSpin0Cw5Turns));
  ASSERT_TRUE(spin.ok());
  EXPECT_EQ(spin->id, 0);
  EXPECT_TRUE(spin->clockwise);
  EXPECT_EQ(spin->mode, SpinMode::kTurns);
  EXPECT_EQ(spin->speed_dps, 100);
  EXPECT_EQ(spin->value, 5);
  const Decoded<SpinCommand> ccw = decodeSpin(request(kSpin0CcwContinuous));
  ASSERT_TRUE(ccw.ok());
  EXPECT_FALSE(ccw->clockwise);
  EXPECT_EQ(ccw->mode, SpinMode::kContinuous);
  EXPECT_EQ(decodeSpin(request(kRotate2To90In500)).error(), DecodeError::kUnknownCommand);
}

}  // namespace
}  // namespace serial_robot_driver::protocol::servo
