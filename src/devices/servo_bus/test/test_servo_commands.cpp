// The bus servo command table and the typed requests/answers built on it: the golden frames of
// test/support (written by hand from docs/protocols.md, section 3) decode to what they say, every
// golden request fits its row of the table, and typed answers re-encode to the golden bytes.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_commands.h"
#include "support/golden_frames.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using Bytes = std::vector<uint8_t>;
using namespace golden::servo;  // NOLINT: the shared golden frames

Packet request(const Bytes& frame) {
  const protocol::Decoded<Packet> packet = decodeRequest(frame.data(), frame.size());
  EXPECT_TRUE(packet.ok());
  return packet.ok() ? *packet : Packet{};
}

Packet response(const Bytes& frame) {
  const protocol::Decoded<Packet> packet = decodeResponse(frame.data(), frame.size());
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

// Written by hand from the table of docs/protocols.md, section 3: N of each request and answer
// (a parameter value is 1..4 bytes, the user block 32) and where the result byte is.
struct ExpectedSizes {
  Command cmd;
  ContentSize request;
  ContentSize answer;
  int result_index;
};
constexpr std::array<ExpectedSizes, kMaxCommand> kExpectedSizes = {{
    {Command::kPing, {1, 1}, {1, 1}, kNoResult},
    {Command::kResetUserData, {1, 1}, {2, 2}, 1},
    {Command::kReadData, {2, 2}, {3, 6}, kNoResult},
    {Command::kWriteData, {3, 6}, {3, 3}, 2},
    {Command::kReadBatchData, {1, 1}, {33, 33}, kNoResult},
    {Command::kWriteBatchData, {33, 33}, {2, 2}, 1},
    {Command::kSpin, {6, 6}, {2, 2}, 1},
    {Command::kRotate, {7, 7}, {2, 2}, 1},
    {Command::kDamping, {3, 3}, {2, 2}, 1},
    {Command::kReadAngle, {1, 1}, {3, 3}, kNoResult},
    {Command::kMoveByInterval, {11, 11}, {2, 2}, 1},
    {Command::kMoveByVelocity, {11, 11}, {2, 2}, 1},
    {Command::kMultiTurnMove, {11, 11}, {2, 2}, 1},
    {Command::kMultiTurnMoveByInterval, {15, 15}, {2, 2}, 1},
    {Command::kMultiTurnMoveByVelocity, {13, 13}, {2, 2}, 1},
    {Command::kReadMultiTurnAngle, {1, 1}, {7, 7}, kNoResult},
}};

TEST(ServoCommandTable, SizesAndResultBytesAreTheDocumentedOnes) {
  for (const CommandInfo& info : commandTable()) {
    const ExpectedSizes& expected =
        kExpectedSizes[static_cast<std::size_t>(info.cmd) - kMinCommand];
    ASSERT_EQ(expected.cmd, info.cmd) << info.name;
    EXPECT_EQ(info.request.min, expected.request.min) << info.name;
    EXPECT_EQ(info.request.max, expected.request.max) << info.name;
    EXPECT_EQ(info.answer.min, expected.answer.min) << info.name;
    EXPECT_EQ(info.answer.max, expected.answer.max) << info.name;
    EXPECT_EQ(info.result_index, expected.result_index) << info.name;
  }
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
  const protocol::Decoded<AngleAnswer> angle = decodeAngleAnswer(response(kReadAngle0Reply902));
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
  const protocol::Decoded<int64_t> mv =
      decodeReadDataAnswer(response(kReadVoltage3Reply), *voltage);
  ASSERT_TRUE(mv.ok());
  EXPECT_EQ(*mv, 7400);
  EXPECT_EQ(readDataAnswerContent(3, *voltage, 7400), contentOf(kReadVoltage3Reply));
  const protocol::Decoded<int64_t> low =
      decodeReadDataAnswer(response(kReadLimitLow3Reply), *limit_low);
  ASSERT_TRUE(low.ok());
  EXPECT_EQ(*low, -900);
  EXPECT_EQ(readDataAnswerContent(3, *limit_low, -900), contentOf(kReadLimitLow3Reply));
}

TEST(ServoTypedRequests, MovesDecodeToWhatTheirGoldenBytesSay) {
  const protocol::Decoded<MoveCommand> rotate = decodeMove(request(kRotate2To90In500));
  ASSERT_TRUE(rotate.ok());
  EXPECT_EQ(rotate->cmd, Command::kRotate);
  EXPECT_EQ(rotate->id, 2);
  EXPECT_EQ(rotate->angle_decidegrees, 900);
  EXPECT_EQ(rotate->interval_ms, 500u);
  EXPECT_EQ(rotate->ramps.power_mw, 0);

  const protocol::Decoded<MoveCommand> by_velocity = decodeMove(request(kMoveByVelocity1ToMinus90));
  ASSERT_TRUE(by_velocity.ok());
  EXPECT_EQ(by_velocity->angle_decidegrees, -900);
  EXPECT_EQ(by_velocity->velocity_decidegrees_per_s, 3600);
  EXPECT_EQ(by_velocity->ramps.accel_ms, 100);
  EXPECT_EQ(by_velocity->ramps.decel_ms, 100);

  const protocol::Decoded<MoveCommand> multi =
      decodeMove(request(kMultiTurnMoveByInterval1ToMinus360));
  ASSERT_TRUE(multi.ok());
  EXPECT_EQ(multi->angle_decidegrees, -3600);
  EXPECT_EQ(multi->interval_ms, 1000u);
  EXPECT_EQ(multi->ramps.accel_ms, 200);
  EXPECT_TRUE(isMultiTurn(multi->cmd));
  EXPECT_FALSE(isByVelocity(multi->cmd));

  const protocol::Decoded<MoveCommand> plain = decodeMove(request(kMultiTurnMove1To720));
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->angle_decidegrees, 7200);
  EXPECT_EQ(plain->interval_ms, 2000u);
  EXPECT_FALSE(hasRamps(plain->cmd));

  const protocol::Decoded<MoveCommand> turns = decodeMove(request(kMultiTurnMoveByVelocity1To3600));
  ASSERT_TRUE(turns.ok());
  EXPECT_EQ(turns->angle_decidegrees, 36000);
  EXPECT_EQ(turns->velocity_decidegrees_per_s, 3600);
}

TEST(ServoTypedRequests, NotAMoveOrWrongSizeIsRefused) {
  EXPECT_EQ(decodeMove(request(kPing3)).error(), protocol::DecodeError::kUnknownCommand);
  Packet short_rotate = request(kRotate2To90In500);
  short_rotate.content_size = 6;
  EXPECT_EQ(decodeMove(short_rotate).error(), protocol::DecodeError::kBadLength);
}

TEST(ServoTypedRequests, SpinDecodesDirectionModeSpeedAndValue) {
  const protocol::Decoded<SpinCommand> spin = decodeSpin(request(kSpin0Cw5Turns));
  ASSERT_TRUE(spin.ok());
  EXPECT_EQ(spin->id, 0);
  EXPECT_TRUE(spin->clockwise);
  EXPECT_EQ(spin->mode, SpinMode::kTurns);
  EXPECT_EQ(spin->speed_dps, 100);
  EXPECT_EQ(spin->value, 5);
  const protocol::Decoded<SpinCommand> ccw = decodeSpin(request(kSpin0CcwContinuous));
  ASSERT_TRUE(ccw.ok());
  EXPECT_FALSE(ccw->clockwise);
  EXPECT_EQ(ccw->mode, SpinMode::kContinuous);
  EXPECT_EQ(decodeSpin(request(kRotate2To90In500)).error(), protocol::DecodeError::kUnknownCommand);
}

// --- encode -> decode for every command of the table ---------------------------------------------

constexpr int32_t kI32Min = std::numeric_limits<int32_t>::min();
constexpr int32_t kI32Max = std::numeric_limits<int32_t>::max();
constexpr int16_t kI16Min = std::numeric_limits<int16_t>::min();
constexpr uint16_t kU16Max = std::numeric_limits<uint16_t>::max();

std::array<uint8_t, kUserBlockSize> countingBlock() {
  std::array<uint8_t, kUserBlockSize> block{};
  for (std::size_t i = 0; i < block.size(); ++i) block[i] = static_cast<uint8_t>(0xA0 + i);
  return block;
}

MoveRamps rampsOf(uint16_t accel, uint16_t decel, uint16_t power) {
  MoveRamps ramps;
  ramps.accel_ms = accel;
  ramps.decel_ms = decel;
  ramps.power_mw = power;
  return ramps;
}

// A move request re-decodes to the values it was built from, and re-encodes to the same bytes.
void expectMove(const Bytes& frame, Command cmd, int32_t angle, uint32_t interval,
                uint16_t velocity, const MoveRamps& ramps) {
  const protocol::Decoded<MoveCommand> move = decodeMove(request(frame));
  ASSERT_TRUE(move.ok()) << commandInfo(cmd).name;
  EXPECT_EQ(move->cmd, cmd);
  EXPECT_EQ(move->id, 7);
  EXPECT_EQ(move->angle_decidegrees, angle);
  EXPECT_EQ(move->interval_ms, interval);
  EXPECT_EQ(move->velocity_decidegrees_per_s, velocity);
  EXPECT_EQ(move->ramps.accel_ms, ramps.accel_ms);
  EXPECT_EQ(move->ramps.decel_ms, ramps.decel_ms);
  EXPECT_EQ(move->ramps.power_mw, ramps.power_mw);
  EXPECT_EQ(encodeMove(*move), frame);
}

// Encodes a request of `cmd` with values at the ends of its fields' ranges and checks that the
// decoders give them back.
Bytes requestRoundTrip(Command cmd) {
  const ParamInfo& limit_low = *findParam("angle_limit_low");
  const MoveRamps ramps = rampsOf(20, kU16Max, 1234);
  const MoveRamps power_only = rampsOf(0, 0, kU16Max);
  Bytes frame;
  switch (cmd) {
    case Command::kPing:
    case Command::kResetUserData:
    case Command::kReadBatchData:
    case Command::kReadAngle:
    case Command::kReadMultiTurnAngle:
      frame = cmd == Command::kPing            ? encodePing(7)
              : cmd == Command::kResetUserData ? encodeResetUserData(7)
              : cmd == Command::kReadBatchData ? encodeReadBatchData(7)
              : cmd == Command::kReadAngle     ? encodeReadAngle(7)
                                               : encodeReadMultiTurnAngle(7);
      EXPECT_EQ(request(frame).id(), 7);
      break;
    case Command::kReadData: {
      frame = encodeReadData(7, 53);
      const protocol::Decoded<DataContent> data = decodeDataContent(request(frame));
      EXPECT_TRUE(data.ok() && data->id == 7 && data->data_id == 53 && data->value_size == 0);
      break;
    }
    case Command::kWriteData: {
      frame = encodeWriteData(7, limit_low, kI16Min);
      const protocol::Decoded<DataContent> data = decodeDataContent(request(frame));
      EXPECT_TRUE(data.ok() && data->id == 7 && data->data_id == limit_low.data_id);
      EXPECT_EQ(readValue(limit_low, data->value.data(), data->value_size), kI16Min);
      break;
    }
    case Command::kWriteBatchData: {
      frame = encodeWriteBatchData(7, countingBlock());
      const auto block = decodeUserBlock(request(frame));
      EXPECT_TRUE(block.ok() && *block == countingBlock());
      break;
    }
    case Command::kSpin: {
      frame = encodeSpin(7, true, SpinMode::kDurationMs, kU16Max, 1);
      const protocol::Decoded<SpinCommand> spin = decodeSpin(request(frame));
      EXPECT_TRUE(spin.ok());
      if (!spin.ok()) break;
      EXPECT_EQ(spin->id, 7);
      EXPECT_TRUE(spin->clockwise);
      EXPECT_EQ(spin->mode, SpinMode::kDurationMs);
      EXPECT_EQ(spin->speed_dps, kU16Max);
      EXPECT_EQ(spin->value, 1);
      EXPECT_EQ(encodeSpin(*spin), frame);
      break;
    }
    case Command::kDamping: {
      frame = encodeDamping(7, kU16Max);
      const protocol::Decoded<uint16_t> power = decodeDamping(request(frame));
      EXPECT_TRUE(power.ok() && *power == kU16Max);
      break;
    }
    case Command::kRotate:
      frame = encodeRotate(7, kI16Min, kU16Max, kU16Max);
      expectMove(frame, cmd, kI16Min, kU16Max, 0, power_only);
      break;
    case Command::kMoveByInterval:
      frame = encodeMoveByInterval(7, -1, kU16Max, ramps);
      expectMove(frame, cmd, -1, kU16Max, 0, ramps);
      break;
    case Command::kMoveByVelocity:
      frame = encodeMoveByVelocity(7, 32767, 7500, ramps);
      expectMove(frame, cmd, 32767, 0, 7500, ramps);
      break;
    case Command::kMultiTurnMove:
      frame = encodeMultiTurnMove(7, kI32Min, 0xFFFFFFFFu, kU16Max);
      expectMove(frame, cmd, kI32Min, 0xFFFFFFFFu, 0, power_only);
      break;
    case Command::kMultiTurnMoveByInterval:
      frame = encodeMultiTurnMoveByInterval(7, kI32Max, 0x12345678u, ramps);
      expectMove(frame, cmd, kI32Max, 0x12345678u, 0, ramps);
      break;
    case Command::kMultiTurnMoveByVelocity:
      frame = encodeMultiTurnMoveByVelocity(7, -3686400, kU16Max, ramps);
      expectMove(frame, cmd, -3686400, 0, kU16Max, ramps);
      break;
  }
  return frame;
}

TEST(ServoCommandRoundTrip, EveryRequestDecodesToWhatWasEncodedAndFitsItsRow) {
  for (const CommandInfo& info : commandTable()) {
    SCOPED_TRACE(info.name);
    const Bytes frame = requestRoundTrip(info.cmd);
    const Packet packet = request(frame);
    EXPECT_EQ(packet.cmd, static_cast<uint8_t>(info.cmd));
    EXPECT_TRUE(info.request.fits(packet.content_size)) << int(packet.content_size);
  }
}

// The answer of `cmd` built by the simulator-side builder, with its result byte (if any) saying
// `ok`, checked against the typed decoders.
Bytes answerRoundTrip(Command cmd, bool ok) {
  const ParamInfo& serial = *findParam("serial_number");
  Bytes content;
  switch (cmd) {
    case Command::kPing:
      content = pingAnswerContent(7);
      break;
    case Command::kReadData: {
      content = readDataAnswerContent(7, serial, 0xFFFFFFFFll);
      Packet packet;
      packet.cmd = static_cast<uint8_t>(cmd);
      packet.content_size = static_cast<uint8_t>(content.size());
      std::copy(content.begin(), content.end(), packet.content.begin());
      const protocol::Decoded<int64_t> value = decodeReadDataAnswer(packet, serial);
      EXPECT_TRUE(value.ok() && *value == 0xFFFFFFFFll);
      break;
    }
    case Command::kWriteData:
      content = writeDataAnswerContent(7, serial.data_id, ok);
      break;
    case Command::kReadBatchData:
      content = userBlockAnswerContent(7, countingBlock());
      break;
    case Command::kReadAngle:
      content = angleAnswerContent({7, kI16Min});
      break;
    case Command::kReadMultiTurnAngle:
      content = multiTurnAngleContent({7, kI32Min, -2});
      break;
    default:
      content = resultAnswerContent(7, ok);
      break;
  }
  return encodeResponse(cmd, content);
}

TEST(ServoCommandRoundTrip, EveryAnswerDecodesToWhatWasEncodedAndFitsItsRow) {
  for (const CommandInfo& info : commandTable()) {
    SCOPED_TRACE(info.name);
    for (bool ok : {true, false}) {
      const Packet packet = response(answerRoundTrip(info.cmd, ok));
      EXPECT_EQ(packet.cmd, static_cast<uint8_t>(info.cmd));
      EXPECT_EQ(packet.id(), 7);
      EXPECT_TRUE(info.answer.fits(packet.content_size)) << int(packet.content_size);
      if (info.result_index != kNoResult) {
        EXPECT_EQ(packet.content[info.result_index], ok ? 1 : 0);
      }
      if (info.cmd == Command::kWriteData) {
        const protocol::Decoded<DataContent> data = decodeDataContent(packet);
        EXPECT_TRUE(data.ok() && data->data_id == findParam("serial_number")->data_id);
      }
      if (info.cmd == Command::kReadBatchData) {
        const auto block = decodeUserBlock(packet);
        EXPECT_TRUE(block.ok() && *block == countingBlock());
      }
      if (info.cmd == Command::kReadAngle) {
        const protocol::Decoded<AngleAnswer> angle = decodeAngleAnswer(packet);
        EXPECT_TRUE(angle.ok() && angle->angle_decidegrees == kI16Min);
      }
      if (info.cmd == Command::kReadMultiTurnAngle) {
        const protocol::Decoded<MultiTurnAngle> angle = decodeMultiTurnAngle(packet);
        ASSERT_TRUE(angle.ok());
        EXPECT_EQ(angle->angle_decidegrees, kI32Min);
        EXPECT_EQ(angle->turns, -2);
      }
    }
  }
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
