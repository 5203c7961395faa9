// The CONTENT of every bus servo request and answer as one field list each (docs/protocols.md,
// section 3). The codec encodes and decodes with these lists and the command table takes its sizes
// and result bytes from them: this is the one place that spells a command's bytes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_params.h"
#include "serial_robot_driver/protocol/wire_fields.h"

namespace serial_robot_driver::devices::servo_bus::layout {

using protocol::wire::field;
using protocol::wire::Field;
using protocol::wire::FieldList;
using protocol::wire::listOf;
using protocol::wire::nestedField;
constexpr auto kLE = protocol::wire::ByteOrder::kLittle;

/// The answer field that says 1 (ok) or 0 (failed); the command table points at it.
constexpr std::string_view kResultField = "result";

// Records of the contents that have no typed struct of their own in servo_bus_codec.h.
struct IdContent {
  uint8_t id = 0;
};
struct DataIdContent {
  uint8_t id = 0;
  uint8_t data_id = 0;
};
struct ResultContent {
  uint8_t id = 0;
  uint8_t result = 0;
};
struct DataIdResult {
  uint8_t id = 0;
  uint8_t data_id = 0;
  uint8_t result = 0;
};
struct PowerContent {
  uint8_t id = 0;
  uint16_t power_mw = 0;
};

constexpr std::array<Field<IdContent>, 1> kId = {
    {field<&IdContent::id>("id", protocol::wire::kU8, kLE)}};
constexpr std::array<Field<DataIdContent>, 2> kDataId = {{
    field<&DataIdContent::id>("id", protocol::wire::kU8, kLE),
    field<&DataIdContent::data_id>("data_id", protocol::wire::kU8, kLE),
}};
constexpr std::array<Field<ResultContent>, 2> kIdResult = {{
    field<&ResultContent::id>("id", protocol::wire::kU8, kLE),
    field<&ResultContent::result>(kResultField, protocol::wire::kU8, kLE),
}};
constexpr std::array<Field<DataIdResult>, 3> kDataIdResult = {{
    field<&DataIdResult::id>("id", protocol::wire::kU8, kLE),
    field<&DataIdResult::data_id>("data_id", protocol::wire::kU8, kLE),
    field<&DataIdResult::result>(kResultField, protocol::wire::kU8, kLE),
}};
constexpr std::array<Field<PowerContent>, 2> kDamping = {{
    field<&PowerContent::id>("id", protocol::wire::kU8, kLE),
    field<&PowerContent::power_mw>("power", protocol::wire::kU16, kLE, "mW"),
}};

// SPIN method byte: bit 7 direction, bits 1..0 mode; the other bits are not part of SPIN.
constexpr uint8_t kSpinDirectionBit = 0x80;
constexpr uint8_t kSpinModeMask = 0x03;
inline int64_t spinMethodOf(const SpinCommand& spin) {
  return spinMethod(spin.clockwise, spin.mode);
}
inline void setSpinMethod(SpinCommand& spin, int64_t method) {
  spin.clockwise = (method & kSpinDirectionBit) != 0;
  spin.mode = static_cast<SpinMode>(method & kSpinModeMask);
}
constexpr std::array<Field<SpinCommand>, 4> kSpin = {{
    field<&SpinCommand::id>("id", protocol::wire::kU8, kLE),
    {"method", protocol::wire::kU8, kLE, "", &spinMethodOf, &setSpinMethod},
    field<&SpinCommand::speed_dps>("speed", protocol::wire::kU16, kLE, "deg/s"),
    field<&SpinCommand::value>("value", protocol::wire::kU16, kLE, "turns or ms"),
}};

// The moves: ROTATE and CMD 11..15 differ in the angle's and interval's widths and in which of
// velocity, interval and ramps they carry.
constexpr auto kMoveId = field<&MoveCommand::id>("id", protocol::wire::kU8, kLE);
constexpr auto kAngle16 =
    field<&MoveCommand::angle_decidegrees>("angle", protocol::wire::kI16, kLE, "0.1deg");
constexpr auto kAngle32 =
    field<&MoveCommand::angle_decidegrees>("angle", protocol::wire::kI32, kLE, "0.1deg");
constexpr auto kInterval16 =
    field<&MoveCommand::interval_ms>("interval", protocol::wire::kU16, kLE, "ms");
constexpr auto kInterval32 =
    field<&MoveCommand::interval_ms>("interval", protocol::wire::kU32, kLE, "ms");
constexpr auto kVelocity = field<&MoveCommand::velocity_decidegrees_per_s>(
    "velocity", protocol::wire::kU16, kLE, "0.1deg/s");
constexpr auto kAccel = nestedField<&MoveCommand::ramps, &MoveRamps::accel_ms>(
    "accel", protocol::wire::kU16, kLE, "ms");
constexpr auto kDecel = nestedField<&MoveCommand::ramps, &MoveRamps::decel_ms>(
    "decel", protocol::wire::kU16, kLE, "ms");
constexpr auto kPower = nestedField<&MoveCommand::ramps, &MoveRamps::power_mw>(
    "power", protocol::wire::kU16, kLE, "mW");

constexpr std::array<Field<MoveCommand>, 4> kRotate = {{kMoveId, kAngle16, kInterval16, kPower}};
constexpr std::array<Field<MoveCommand>, 6> kMoveByInterval = {
    {kMoveId, kAngle16, kInterval16, kAccel, kDecel, kPower}};
constexpr std::array<Field<MoveCommand>, 6> kMoveByVelocity = {
    {kMoveId, kAngle16, kVelocity, kAccel, kDecel, kPower}};
constexpr std::array<Field<MoveCommand>, 4> kMultiTurnMove = {
    {kMoveId, kAngle32, kInterval32, kPower}};
constexpr std::array<Field<MoveCommand>, 6> kMultiTurnMoveByInterval = {
    {kMoveId, kAngle32, kInterval32, kAccel, kDecel, kPower}};
constexpr std::array<Field<MoveCommand>, 6> kMultiTurnMoveByVelocity = {
    {kMoveId, kAngle32, kVelocity, kAccel, kDecel, kPower}};

/// The field list of a move; empty for a command that is not one.
constexpr FieldList<MoveCommand> moveFields(Command cmd) {
  switch (cmd) {
    case Command::kRotate:
      return listOf(kRotate);
    case Command::kMoveByInterval:
      return listOf(kMoveByInterval);
    case Command::kMoveByVelocity:
      return listOf(kMoveByVelocity);
    case Command::kMultiTurnMove:
      return listOf(kMultiTurnMove);
    case Command::kMultiTurnMoveByInterval:
      return listOf(kMultiTurnMoveByInterval);
    case Command::kMultiTurnMoveByVelocity:
      return listOf(kMultiTurnMoveByVelocity);
    default:
      return {};
  }
}

constexpr std::array<Field<AngleAnswer>, 2> kAngleAnswer = {{
    field<&AngleAnswer::id>("id", protocol::wire::kU8, kLE),
    field<&AngleAnswer::angle_decidegrees>("angle", protocol::wire::kI16, kLE, "0.1deg"),
}};
constexpr std::array<Field<MultiTurnAngle>, 3> kMultiTurnAngle = {{
    field<&MultiTurnAngle::id>("id", protocol::wire::kU8, kLE),
    field<&MultiTurnAngle::angle_decidegrees>("angle", protocol::wire::kI32, kLE, "0.1deg"),
    field<&MultiTurnAngle::turns>("turns", protocol::wire::kI16, kLE),
}};

// --- what the command table needs of a layout --------------------------------------------------

/// What follows a content's fields: nothing, a parameter value (1..4 bytes by its type) or the
/// 32-byte user block (servo_params.h describes both).
enum class Tail : uint8_t { kNone, kParamValue, kUserBlock };

struct ContentLayout {
  ContentSize size;
  int result_index = kNoResult;
};

template <typename Record, std::size_t N>
constexpr ContentLayout content(const std::array<Field<Record>, N>& fields,
                                Tail tail = Tail::kNone) {
  const FieldList<Record> list = listOf(fields);
  std::size_t min = list.size();
  std::size_t max = min;
  if (tail == Tail::kParamValue) {
    min += smallestTypeSize();
    max += largestTypeSize();
  } else if (tail == Tail::kUserBlock) {
    min += kUserBlockSize;
    max += kUserBlockSize;
  }
  const auto result = list.offsetOf(kResultField);
  return {{static_cast<uint8_t>(min), static_cast<uint8_t>(max)},
          result ? static_cast<int>(*result) : kNoResult};
}

}  // namespace serial_robot_driver::devices::servo_bus::layout
