#include "serial_robot_driver/devices/servo_bus/servo_params.h"

#include <limits>

namespace serial_robot_driver::devices::servo_bus {

namespace {

constexpr int64_t kU8Max = std::numeric_limits<uint8_t>::max();
constexpr int64_t kU16Max = std::numeric_limits<uint16_t>::max();
constexpr int64_t kU32Max = std::numeric_limits<uint32_t>::max();
constexpr int64_t kI16Min = std::numeric_limits<int16_t>::min();
constexpr int64_t kI16Max = std::numeric_limits<int16_t>::max();

constexpr ParamInfo readOnly(ServoDataId id, std::string_view name, ParamType type,
                             std::string_view unit, int64_t max) {
  return ParamInfo{dataId(id), name, type, unit, true, false, 0, max};
}
constexpr ParamInfo readWrite(ServoDataId id, std::string_view name, ParamType type,
                              std::string_view unit, int64_t min, int64_t max) {
  return ParamInfo{dataId(id), name, type, unit, false, false, min, max};
}
/// A write that needs allow_dangerous; `hazard` says why.
constexpr ParamInfo guarded(ServoDataId id, std::string_view name, ParamType type, int64_t min,
                            int64_t max, std::string_view hazard) {
  return ParamInfo{dataId(id), name, type, "", false, true, min, max, hazard};
}
/// An on/off switch: 0 or 1 (datasheet).
constexpr ParamInfo onOff(ServoDataId id, std::string_view name) {
  return ParamInfo{dataId(id), name, ParamType::kU8, "", false, false, 0, 1};
}

constexpr std::string_view kUnreachable = "can make the servo unreachable";
constexpr std::string_view kReservedCell = "is a reserved cell the datasheet does not describe";

// docs/protocols.md, section 3. Ranges are the type's unless the datasheet narrows them.
constexpr std::array<ParamInfo, kParamCount> kParams = {{
    readOnly(ServoDataId::kVoltage, "voltage", ParamType::kU16, "mV", kU16Max),
    readOnly(ServoDataId::kCurrent, "current", ParamType::kU16, "mA", kU16Max),
    readOnly(ServoDataId::kPower, "power", ParamType::kU16, "mW", kU16Max),
    readOnly(ServoDataId::kTemperature, "temperature", ParamType::kU16, "degC", kU16Max),
    readOnly(ServoDataId::kServoStatus, "servo_status", ParamType::kU8, "", kU8Max),
    readOnly(ServoDataId::kServoType, "servo_type", ParamType::kU16, "", kU16Max),
    readOnly(ServoDataId::kFirmwareVersion, "firmware_version", ParamType::kU16, "", kU16Max),
    readOnly(ServoDataId::kSerialNumber, "serial_number", ParamType::kU32, "", kU32Max),
    guarded(ServoDataId::kReserved32, "reserved_32", ParamType::kU8, 0, kU8Max, kReservedCell),
    // 1 makes every motion command queued and answered at completion: commands sent without
    // waiting then pile up behind each other and their answers collide with later transactions.
    guarded(ServoDataId::kResponseSwitch, "response_switch", ParamType::kU8, 0, 1,
            "changes how motion commands are queued and answered on the shared bus"),
    // Changes the address the servo answers to: a mistake loses the servo.
    guarded(ServoDataId::kServoId, "servo_id", ParamType::kU8, 0, 254, kUnreachable),
    guarded(ServoDataId::kReserved35, "reserved_35", ParamType::kU8, 0, kU8Max, kReservedCell),
    // Takes effect at once: the servo stops understanding us at our baud rate.
    guarded(ServoDataId::kBaudrate, "baudrate", ParamType::kU8, 1, 7, kUnreachable),
    // 1 limit the power, 2 release the torque.
    readWrite(ServoDataId::kStallProtectMode, "stall_protect_mode", ParamType::kU8, "", 1, 2),
    readWrite(ServoDataId::kStallPowerLimit, "stall_power_limit", ParamType::kU16, "mW", 0,
              kU16Max),
    readWrite(ServoDataId::kOverVoltLow, "over_volt_low", ParamType::kU16, "mV", 0, kU16Max),
    readWrite(ServoDataId::kOverVoltHigh, "over_volt_high", ParamType::kU16, "mV", 0, kU16Max),
    readWrite(ServoDataId::kOverTemperature, "over_temperature", ParamType::kU16, "degC", 0,
              kU16Max),
    readWrite(ServoDataId::kOverPower, "over_power", ParamType::kU16, "mW", 0, kU16Max),
    readWrite(ServoDataId::kOverCurrent, "over_current", ParamType::kU16, "mA", 0, kU16Max),
    onOff(ServoDataId::kAccelSwitch, "accel_switch"),
    guarded(ServoDataId::kReserved45, "reserved_45", ParamType::kU8, 0, kU8Max, kReservedCell),
    onOff(ServoDataId::kPoLockSwitch, "po_lock_switch"),
    onOff(ServoDataId::kWbLockSwitch, "wb_lock_switch"),
    onOff(ServoDataId::kAngleLimitSwitch, "angle_limit_switch"),
    onOff(ServoDataId::kSoftStartSwitch, "soft_start_switch"),
    readWrite(ServoDataId::kSoftStartTime, "soft_start_time", ParamType::kU16, "ms", 0, kU16Max),
    readWrite(ServoDataId::kAngleLimitHigh, "angle_limit_high", ParamType::kI16, "0.1deg", kI16Min,
              kI16Max),
    readWrite(ServoDataId::kAngleLimitLow, "angle_limit_low", ParamType::kI16, "0.1deg", kI16Min,
              kI16Max),
    readWrite(ServoDataId::kAngleMidOffset, "angle_mid_offset", ParamType::kI16, "0.1deg", kI16Min,
              kI16Max),
}};

// The vendor's spellings, accepted so that names copied from its datasheet work.
struct NameAlias {
  std::string_view vendor;
  std::string_view canonical;
};
constexpr std::array<NameAlias, 2> kAliases = {{
    {"temprature", "temperature"},
    {"over_temprature", "over_temperature"},
}};

// Parses a plain decimal data_id ("51"); no sign, no spaces, no trailing characters.
std::optional<uint8_t> parseDataId(std::string_view text) {
  constexpr std::size_t kMaxDigits = 3;
  if (text.empty() || text.size() > kMaxDigits) return std::nullopt;
  int value = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
  }
  if (value > std::numeric_limits<uint8_t>::max()) return std::nullopt;
  return static_cast<uint8_t>(value);
}

std::string label(const ParamInfo& param) {
  return "'" + std::string(param.name) + "' (id " + std::to_string(param.data_id) + ")";
}

}  // namespace

int64_t typeMin(ParamType type) { return type == ParamType::kI16 ? kI16Min : 0; }

int64_t typeMax(ParamType type) {
  switch (type) {
    case ParamType::kU8:
      return kU8Max;
    case ParamType::kU16:
      return kU16Max;
    case ParamType::kU32:
      return kU32Max;
    case ParamType::kI16:
      return kI16Max;
  }
  return 0;
}

const std::array<ParamInfo, kParamCount>& paramTable() { return kParams; }

const ParamInfo* findParamById(uint8_t data_id) {
  for (const ParamInfo& param : kParams) {
    if (param.data_id == data_id) return &param;
  }
  return nullptr;
}

const ParamInfo* findParam(std::string_view name_or_id) {
  for (const NameAlias& alias : kAliases) {
    if (name_or_id == alias.vendor) {
      name_or_id = alias.canonical;
      break;
    }
  }
  for (const ParamInfo& param : kParams) {
    if (param.name == name_or_id) return &param;
  }
  if (const std::optional<uint8_t> id = parseDataId(name_or_id)) return findParamById(*id);
  return nullptr;
}

WriteCheck checkWrite(const ParamInfo& param, int64_t value, bool allow_dangerous) {
  if (param.read_only) return WriteCheck::kReadOnly;
  if (value < param.min || value > param.max) return WriteCheck::kOutOfRange;
  if (param.dangerous && !allow_dangerous) return WriteCheck::kDangerous;
  return WriteCheck::kOk;
}

std::string describe(WriteCheck check, const ParamInfo& param, int64_t value) {
  switch (check) {
    case WriteCheck::kOk:
      return "value " + std::to_string(value) + " for parameter " + label(param) + " is valid";
    case WriteCheck::kReadOnly:
      return "parameter " + label(param) + " is read-only";
    case WriteCheck::kOutOfRange:
      return "value " + std::to_string(value) + " out of range " + std::to_string(param.min) +
             ".." + std::to_string(param.max) + " for parameter " + label(param);
    case WriteCheck::kDangerous:
      return "writing parameter " + label(param) + " " +
             std::string(param.hazard.empty() ? kUnreachable : param.hazard) +
             "; refused because dangerous writes are not allowed";
  }
  return "unknown write check result";
}

std::optional<int64_t> readValue(const ParamInfo& param, const uint8_t* data, std::size_t size) {
  if (size != typeSize(param.type)) return std::nullopt;
  return protocol::wire::readInteger(data, wireType(param.type),
                                     protocol::wire::ByteOrder::kLittle);
}

std::size_t writeValue(const ParamInfo& param, int64_t value, uint8_t* out) {
  // Two's complement: the low bytes of a negative i16 are its wire form.
  protocol::wire::writeInteger(out, value, wireType(param.type),
                               protocol::wire::ByteOrder::kLittle);
  return typeSize(param.type);
}

std::optional<std::size_t> userBlockOffset(const ParamInfo& param) {
  if (param.data_id < kFirstUserParamId || param.data_id > kLastUserParamId) return std::nullopt;
  std::size_t offset = 0;
  for (const ParamInfo& other : kParams) {
    if (other.data_id < kFirstUserParamId) continue;
    if (other.data_id == param.data_id) return offset;
    offset += typeSize(other.type);
  }
  return std::nullopt;
}

std::array<uint8_t, kUserBlockSize> packUserBlock(
    const std::function<int64_t(const ParamInfo&)>& value_of) {
  std::array<uint8_t, kUserBlockSize> block{};
  for (const ParamInfo& param : kParams) {
    if (const std::optional<std::size_t> offset = userBlockOffset(param)) {
      writeValue(param, value_of(param), &block[*offset]);
    }
  }
  return block;
}

std::vector<std::pair<const ParamInfo*, int64_t>> unpackUserBlock(
    const std::array<uint8_t, kUserBlockSize>& block) {
  std::vector<std::pair<const ParamInfo*, int64_t>> values;
  for (const ParamInfo& param : kParams) {
    const std::optional<std::size_t> offset = userBlockOffset(param);
    if (!offset) continue;
    // The table's user parameters fill the block exactly (test_servo_params checks it).
    const std::size_t size = typeSize(param.type);
    values.emplace_back(&param, *readValue(param, &block[*offset], size));
  }
  return values;
}

}  // namespace serial_robot_driver::devices::servo_bus
