#include "serial_robot_driver/protocol/servo_commands.h"

namespace serial_robot_driver::protocol::servo {

namespace {

constexpr ContentSize exactly(std::size_t size) {
  return {static_cast<uint8_t>(size), static_cast<uint8_t>(size)};
}
// id, data_id, then a parameter value of 1..4 bytes (its type, servo_params.h).
constexpr ContentSize kWithParamValue = {2 + 1, 2 + 4};
constexpr ContentSize kIdOnly = exactly(1);
constexpr ContentSize kIdResult = exactly(2);
constexpr ContentSize kUserBlock = exactly(1 + kUserBlockSize);

// Request layouts of the motions (little-endian after the id):
//   SPIN      id, method u8, speed u16, value u16
//   ROTATE    id, angle i16, interval u16, power u16
//   DAMPING   id, power u16
//   CMD 11    id, angle i16, interval u16, accel u16, decel u16, power u16
//   CMD 12    id, angle i16, velocity u16, accel u16, decel u16, power u16
//   CMD 13    id, angle i32, interval u32, power u16
//   CMD 14    id, angle i32, interval u32, accel u16, decel u16, power u16
//   CMD 15    id, angle i32, velocity u16, accel u16, decel u16, power u16
// Answers: READ_ANGLE id, angle i16; CMD 16 id, angle i32, turns i16; a motion id, result.
constexpr std::array<CommandInfo, kMaxCommand> kTable = {{
    {Command::kPing, "PING", kIdOnly, kIdOnly, Answers::kAlways, kNoResult},
    {Command::kResetUserData, "RESET_USER_DATA", kIdOnly, kIdResult, Answers::kAlways, 1},
    {Command::kReadData, "READ_DATA", exactly(2), kWithParamValue, Answers::kAlways, kNoResult},
    {Command::kWriteData, "WRITE_DATA", kWithParamValue, exactly(3), Answers::kAlways, 2},
    {Command::kReadBatchData, "READ_BATCH_DATA", kIdOnly, kUserBlock, Answers::kAlways, kNoResult},
    {Command::kWriteBatchData, "WRITE_BATCH_DATA", kUserBlock, kIdResult, Answers::kAlways, 1},
    {Command::kSpin, "SPIN", exactly(6), kIdResult, Answers::kWhenResponseSwitch, 1},
    {Command::kRotate, "ROTATE", exactly(7), kIdResult, Answers::kWhenResponseSwitch, 1},
    {Command::kDamping, "DAMPING", exactly(3), kIdResult, Answers::kWhenResponseSwitch, 1},
    {Command::kReadAngle, "READ_ANGLE", kIdOnly, exactly(3), Answers::kAlways, kNoResult},
    {Command::kMoveByInterval, "MOVE_BY_INTERVAL (CMD 11)", exactly(11), kIdResult,
     Answers::kWhenResponseSwitch, 1},
    {Command::kMoveByVelocity, "MOVE_BY_VELOCITY (CMD 12)", exactly(11), kIdResult,
     Answers::kWhenResponseSwitch, 1},
    {Command::kMultiTurnMove, "MULTI_TURN_MOVE (CMD 13)", exactly(11), kIdResult,
     Answers::kWhenResponseSwitch, 1},
    {Command::kMultiTurnMoveByInterval, "MULTI_TURN_MOVE_BY_INTERVAL (CMD 14)", exactly(15),
     kIdResult, Answers::kWhenResponseSwitch, 1},
    {Command::kMultiTurnMoveByVelocity, "MULTI_TURN_MOVE_BY_VELOCITY (CMD 15)", exactly(13),
     kIdResult, Answers::kWhenResponseSwitch, 1},
    {Command::kReadMultiTurnAngle, "READ_MULTI_TURN_ANGLE (CMD 16)", kIdOnly,
     exactly(kMultiTurnAngleAnswerSize), Answers::kAlways, kNoResult},
}};

constexpr bool inCommandOrder() {
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    if (static_cast<std::size_t>(kTable[i].cmd) != i + kMinCommand) return false;
  }
  return true;
}
static_assert(inCommandOrder(), "commandTable() is indexed by CMD");

}  // namespace

const std::array<CommandInfo, kMaxCommand>& commandTable() { return kTable; }

const CommandInfo& commandInfo(Command cmd) {
  return kTable[static_cast<std::size_t>(cmd) - kMinCommand];
}

}  // namespace serial_robot_driver::protocol::servo
