// The UART bus servo parameter table (docs/protocols.md, section 3): data_id, name, wire type, unit
// and safety flags in one place, so validation, encoding and the services read the same facts.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "serial_robot_driver/protocol/wire_fields.h"

namespace serial_robot_driver::devices::servo_bus {

/// Every data_id of the parameter table; the one place where these numbers are spelled.
enum class ServoDataId : uint8_t {
  kVoltage = 1,
  kCurrent = 2,
  kPower = 3,
  kTemperature = 4,
  kServoStatus = 5,
  kServoType = 6,
  kFirmwareVersion = 7,
  kSerialNumber = 8,
  kReserved32 = 32,
  kResponseSwitch = 33,
  kServoId = 34,
  kReserved35 = 35,
  kBaudrate = 36,
  kStallProtectMode = 37,
  kStallPowerLimit = 38,
  kOverVoltLow = 39,
  kOverVoltHigh = 40,
  kOverTemperature = 41,
  kOverPower = 42,
  kOverCurrent = 43,
  kAccelSwitch = 44,
  kReserved45 = 45,
  kPoLockSwitch = 46,
  kWbLockSwitch = 47,
  kAngleLimitSwitch = 48,
  kSoftStartSwitch = 49,
  kSoftStartTime = 50,
  kAngleLimitHigh = 51,
  kAngleLimitLow = 52,
  kAngleMidOffset = 53,
};
constexpr uint8_t dataId(ServoDataId id) { return static_cast<uint8_t>(id); }
/// The id RESET_USER_DATA gives a servo.
constexpr uint8_t kServoIdAfterReset = 0;

enum class ParamType { kU8, kU16, kU32, kI16 };
constexpr std::array<ParamType, 4> kParamTypes = {ParamType::kU8, ParamType::kU16, ParamType::kU32,
                                                  ParamType::kI16};

/// How a value of `type` goes on the wire (little-endian, as all of the servo bus).
constexpr protocol::wire::WireType wireType(ParamType type) {
  switch (type) {
    case ParamType::kU8:
      return protocol::wire::kU8;
    case ParamType::kU16:
      return protocol::wire::kU16;
    case ParamType::kU32:
      return protocol::wire::kU32;
    case ParamType::kI16:
      return protocol::wire::kI16;
  }
  return protocol::wire::reserved(0);
}
constexpr std::size_t typeSize(ParamType type) { return wireType(type).width; }
/// The narrowest and widest parameter value on the wire.
constexpr std::size_t smallestTypeSize() {
  std::size_t smallest = typeSize(kParamTypes[0]);
  for (ParamType type : kParamTypes) smallest = std::min(smallest, typeSize(type));
  return smallest;
}
constexpr std::size_t largestTypeSize() {
  std::size_t largest = 0;
  for (ParamType type : kParamTypes) largest = std::max(largest, typeSize(type));
  return largest;
}
int64_t typeMin(ParamType type);
int64_t typeMax(ParamType type);

struct ParamInfo {
  uint8_t data_id;
  std::string_view name;
  ParamType type;
  std::string_view unit;  ///< "mV", "mA", "mW", "degC", "ms", "0.1deg" or "" (raw)
  bool read_only;
  bool dangerous;  ///< refused unless explicitly allowed (see `hazard`)
  int64_t min;     ///< allowed range for writes (the type's range unless the datasheet narrows it)
  int64_t max;
  std::string_view hazard = {};  ///< why a dangerous write is guarded, for the message
};

constexpr std::size_t kParamCount = 30;
const std::array<ParamInfo, kParamCount>& paramTable();

/// Looks a parameter up by name ("voltage"; both "temperature" and the vendor's "temprature") or
/// by its numeric data_id written as text ("51"). nullptr when unknown.
const ParamInfo* findParam(std::string_view name_or_id);
const ParamInfo* findParamById(uint8_t data_id);

/// The read-write user block (ids 32..53 packed in order) is 32 bytes.
constexpr std::size_t kUserBlockSize = 32;
constexpr uint8_t kFirstUserParamId = dataId(ServoDataId::kReserved32);
constexpr uint8_t kLastUserParamId = dataId(ServoDataId::kAngleMidOffset);

enum class WriteCheck { kOk, kReadOnly, kOutOfRange, kDangerous };
/// Checks a write before any byte is encoded. `allow_dangerous` arms servo_id/baudrate writes.
WriteCheck checkWrite(const ParamInfo& param, int64_t value, bool allow_dangerous);
/// A sentence for a failed check, naming the parameter and the allowed range.
std::string describe(WriteCheck check, const ParamInfo& param, int64_t value);

/// Reads a value of `param`'s type from little-endian bytes (`size` must be typeSize).
std::optional<int64_t> readValue(const ParamInfo& param, const uint8_t* data, std::size_t size);
/// Writes a value already checked by checkWrite; returns the number of bytes written.
std::size_t writeValue(const ParamInfo& param, int64_t value, uint8_t* out);

/// Byte offset of a user-block parameter inside the 32-byte block, nullopt for read-only ones.
std::optional<std::size_t> userBlockOffset(const ParamInfo& param);

/// The user block with each read-write parameter's value, as `value_of` gives it, at its offset.
std::array<uint8_t, kUserBlockSize> packUserBlock(
    const std::function<int64_t(const ParamInfo&)>& value_of);
/// Every parameter of a user block with its value, in block order.
std::vector<std::pair<const ParamInfo*, int64_t>> unpackUserBlock(
    const std::array<uint8_t, kUserBlockSize>& block);

}  // namespace serial_robot_driver::devices::servo_bus
