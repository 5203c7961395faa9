#include "serial_robot_driver/devices/servo_bus/servo_commands.h"

#include "servo_layouts.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

using layout::content;
using layout::Tail;

constexpr CommandInfo row(Command cmd, const char* name, const layout::ContentLayout& request,
                          const layout::ContentLayout& answer, Answers answers) {
  return {cmd, name, request.size, answer.size, answers, answer.result_index};
}

// Sizes and result bytes come from the field lists the codec encodes and decodes with.
constexpr auto kMotion = Answers::kWhenResponseSwitch;
constexpr auto kMotionDone = content(layout::kIdResult);
constexpr std::array<CommandInfo, kMaxCommand> kTable = {{
    row(Command::kPing, "PING", content(layout::kId), content(layout::kId), Answers::kAlways),
    row(Command::kResetUserData, "RESET_USER_DATA", content(layout::kId),
        content(layout::kIdResult), Answers::kAlways),
    row(Command::kReadData, "READ_DATA", content(layout::kDataId),
        content(layout::kDataId, Tail::kParamValue), Answers::kAlways),
    row(Command::kWriteData, "WRITE_DATA", content(layout::kDataId, Tail::kParamValue),
        content(layout::kDataIdResult), Answers::kAlways),
    row(Command::kReadBatchData, "READ_BATCH_DATA", content(layout::kId),
        content(layout::kId, Tail::kUserBlock), Answers::kAlways),
    row(Command::kWriteBatchData, "WRITE_BATCH_DATA", content(layout::kId, Tail::kUserBlock),
        content(layout::kIdResult), Answers::kAlways),
    row(Command::kSpin, "SPIN", content(layout::kSpin), kMotionDone, kMotion),
    row(Command::kRotate, "ROTATE", content(layout::kRotate), kMotionDone, kMotion),
    row(Command::kDamping, "DAMPING", content(layout::kDamping), kMotionDone, kMotion),
    row(Command::kReadAngle, "READ_ANGLE", content(layout::kId), content(layout::kAngleAnswer),
        Answers::kAlways),
    row(Command::kMoveByInterval, "MOVE_BY_INTERVAL (CMD 11)", content(layout::kMoveByInterval),
        kMotionDone, kMotion),
    row(Command::kMoveByVelocity, "MOVE_BY_VELOCITY (CMD 12)", content(layout::kMoveByVelocity),
        kMotionDone, kMotion),
    row(Command::kMultiTurnMove, "MULTI_TURN_MOVE (CMD 13)", content(layout::kMultiTurnMove),
        kMotionDone, kMotion),
    row(Command::kMultiTurnMoveByInterval, "MULTI_TURN_MOVE_BY_INTERVAL (CMD 14)",
        content(layout::kMultiTurnMoveByInterval), kMotionDone, kMotion),
    row(Command::kMultiTurnMoveByVelocity, "MULTI_TURN_MOVE_BY_VELOCITY (CMD 15)",
        content(layout::kMultiTurnMoveByVelocity), kMotionDone, kMotion),
    row(Command::kReadMultiTurnAngle, "READ_MULTI_TURN_ANGLE (CMD 16)", content(layout::kId),
        content(layout::kMultiTurnAngle), Answers::kAlways),
}};

constexpr bool inCommandOrder() {
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    if (commandRow(kTable[i].cmd) != i) return false;
  }
  return true;
}
static_assert(inCommandOrder(), "commandTable() is indexed by CMD");

constexpr std::size_t longestContent() {
  std::size_t longest = 0;
  for (const CommandInfo& info : kTable) {
    longest = std::max<std::size_t>(longest, std::max(info.request.max, info.answer.max));
  }
  return longest;
}
static_assert(longestContent() == kMaxContent, "kMaxContent is the longest CONTENT of the table");

}  // namespace

const std::array<CommandInfo, kMaxCommand>& commandTable() { return kTable; }

const CommandInfo& commandInfo(Command cmd) { return kTable[commandRow(cmd)]; }

}  // namespace serial_robot_driver::devices::servo_bus
