// The UART bus servo parameter table, written out by hand from docs/protocols.md, section 3.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_params.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

constexpr int64_t kU8 = 255;
constexpr int64_t kU16 = 65535;

struct ExpectedParam {
  int data_id;
  const char* name;
  ParamType type;
  const char* unit;
  bool read_only;
  bool dangerous;
  int64_t min;
  int64_t max;
};

const ExpectedParam kExpected[] = {
    {1, "voltage", ParamType::kU16, "mV", true, false, 0, kU16},
    {2, "current", ParamType::kU16, "mA", true, false, 0, kU16},
    {3, "power", ParamType::kU16, "mW", true, false, 0, kU16},
    {4, "temperature", ParamType::kU16, "degC", true, false, 0, kU16},
    {5, "servo_status", ParamType::kU8, "", true, false, 0, kU8},
    {6, "servo_type", ParamType::kU16, "", true, false, 0, kU16},
    {7, "firmware_version", ParamType::kU16, "", true, false, 0, kU16},
    {8, "serial_number", ParamType::kU32, "", true, false, 0, 4294967295LL},
    {32, "reserved_32", ParamType::kU8, "", false, true, 0, kU8},
    {33, "response_switch", ParamType::kU8, "", false, true, 0, 1},
    {34, "servo_id", ParamType::kU8, "", false, true, 0, 254},
    {35, "reserved_35", ParamType::kU8, "", false, true, 0, kU8},
    {36, "baudrate", ParamType::kU8, "", false, true, 1, 7},
    {37, "stall_protect_mode", ParamType::kU8, "", false, false, 1, 2},
    {38, "stall_power_limit", ParamType::kU16, "mW", false, false, 0, kU16},
    {39, "over_volt_low", ParamType::kU16, "mV", false, false, 0, kU16},
    {40, "over_volt_high", ParamType::kU16, "mV", false, false, 0, kU16},
    {41, "over_temperature", ParamType::kU16, "degC", false, false, 0, kU16},
    {42, "over_power", ParamType::kU16, "mW", false, false, 0, kU16},
    {43, "over_current", ParamType::kU16, "mA", false, false, 0, kU16},
    {44, "accel_switch", ParamType::kU8, "", false, false, 0, 1},
    {45, "reserved_45", ParamType::kU8, "", false, true, 0, kU8},
    {46, "po_lock_switch", ParamType::kU8, "", false, false, 0, 1},
    {47, "wb_lock_switch", ParamType::kU8, "", false, false, 0, 1},
    {48, "angle_limit_switch", ParamType::kU8, "", false, false, 0, 1},
    {49, "soft_start_switch", ParamType::kU8, "", false, false, 0, 1},
    {50, "soft_start_time", ParamType::kU16, "ms", false, false, 0, kU16},
    {51, "angle_limit_high", ParamType::kI16, "0.1deg", false, false, -32768, 32767},
    {52, "angle_limit_low", ParamType::kI16, "0.1deg", false, false, -32768, 32767},
    {53, "angle_mid_offset", ParamType::kI16, "0.1deg", false, false, -32768, 32767},
};

class ServoParamsTable : public ::testing::TestWithParam<ExpectedParam> {};

TEST_P(ServoParamsTable, FoundByNameWithDatasheetFacts) {
  const ExpectedParam& e = GetParam();
  const ParamInfo* param = findParam(e.name);
  ASSERT_NE(param, nullptr);
  EXPECT_EQ(param->data_id, e.data_id);
  EXPECT_EQ(param->name, e.name);
  EXPECT_EQ(param->type, e.type);
  EXPECT_EQ(param->unit, e.unit);
  EXPECT_EQ(param->read_only, e.read_only);
  EXPECT_EQ(param->dangerous, e.dangerous);
  EXPECT_EQ(param->min, e.min);
  EXPECT_EQ(param->max, e.max);
}

TEST_P(ServoParamsTable, FoundByNumericIdText) {
  const ExpectedParam& e = GetParam();
  const ParamInfo* param = findParam(std::to_string(e.data_id));
  ASSERT_NE(param, nullptr);
  EXPECT_EQ(param->name, e.name);
}

TEST_P(ServoParamsTable, FoundById) {
  const ExpectedParam& e = GetParam();
  const ParamInfo* param = findParamById(static_cast<uint8_t>(e.data_id));
  ASSERT_NE(param, nullptr);
  EXPECT_EQ(param->name, e.name);
  EXPECT_EQ(param, findParam(e.name));  // one table entry, not a copy
}

INSTANTIATE_TEST_SUITE_P(ServoParamsAllThirty, ServoParamsTable, ::testing::ValuesIn(kExpected),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(ServoParams, TableHasExactlyTheThirtyDocumentedIds) {
  ASSERT_EQ(sizeof(kExpected) / sizeof(kExpected[0]), kParamCount);
  std::set<int> ids;
  for (const ParamInfo& param : paramTable()) ids.insert(param.data_id);
  std::set<int> expected_ids;
  for (const ExpectedParam& e : kExpected) expected_ids.insert(e.data_id);
  EXPECT_EQ(ids, expected_ids);
}

TEST(ServoParams, BothTemperatureSpellings) {
  const ParamInfo* vendor = findParam("temprature");
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(vendor, findParam("temperature"));
  EXPECT_EQ(vendor->data_id, 4);
  const ParamInfo* over = findParam("over_temprature");
  ASSERT_NE(over, nullptr);
  EXPECT_EQ(over->data_id, 41);
}

class ServoParamsUnknownName : public ::testing::TestWithParam<std::string> {};

TEST_P(ServoParamsUnknownName, Rejected) { EXPECT_EQ(findParam(GetParam()), nullptr); }

INSTANTIATE_TEST_SUITE_P(ServoParamsRejected, ServoParamsUnknownName,
                         ::testing::Values("51x", "", "-1", "999", "256", "9", "0", " 51", "+51",
                                           "voltagex", "Voltage", "tempreture"));

TEST(ServoParams, LeadingZeroIdIsStillDecimal) {
  const ParamInfo* param = findParam("051");
  ASSERT_NE(param, nullptr);
  EXPECT_EQ(param->name, "angle_limit_high");
}

TEST(ServoParams, UnknownIdIsNull) {
  EXPECT_EQ(findParamById(0), nullptr);
  EXPECT_EQ(findParamById(9), nullptr);
  EXPECT_EQ(findParamById(31), nullptr);
  EXPECT_EQ(findParamById(54), nullptr);
  EXPECT_EQ(findParamById(255), nullptr);
}

TEST(ServoParams, TypeSizesAndRanges) {
  EXPECT_EQ(typeSize(ParamType::kU8), 1u);
  EXPECT_EQ(typeSize(ParamType::kU16), 2u);
  EXPECT_EQ(typeSize(ParamType::kI16), 2u);
  EXPECT_EQ(typeSize(ParamType::kU32), 4u);
  EXPECT_EQ(typeMin(ParamType::kI16), -32768);
  EXPECT_EQ(typeMax(ParamType::kI16), 32767);
  EXPECT_EQ(typeMin(ParamType::kU32), 0);
  EXPECT_EQ(typeMax(ParamType::kU32), 4294967295LL);
  EXPECT_EQ(typeMax(ParamType::kU8), 255);
  EXPECT_EQ(typeMax(ParamType::kU16), 65535);
}

// --- write checks --------------------------------------------------------------------------------

struct WriteCheckCase {
  std::string label;
  const char* name;
  int64_t value;
  bool allow_dangerous;
  WriteCheck expected;
};

const WriteCheckCase kWriteChecks[] = {
    {"ReadOnlyVoltage", "voltage", 5000, true, WriteCheck::kReadOnly},
    // read-only wins over the range check
    {"ReadOnlyBeforeRange", "temperature", -1, false, WriteCheck::kReadOnly},
    // response_switch changes how motion commands are answered: guarded like servo_id.
    {"ResponseSwitchOneNotArmed", "response_switch", 1, false, WriteCheck::kDangerous},
    {"ResponseSwitchOneArmed", "response_switch", 1, true, WriteCheck::kOk},
    {"Reserved32NotArmed", "reserved_32", 0, false, WriteCheck::kDangerous},
    {"Reserved45NotArmed", "reserved_45", 7, false, WriteCheck::kDangerous},
    {"ResponseSwitchTwo", "response_switch", 2, false, WriteCheck::kOutOfRange},
    {"ServoIdNotArmed", "servo_id", 5, false, WriteCheck::kDangerous},
    {"ServoIdArmed", "servo_id", 5, true, WriteCheck::kOk},
    {"ServoIdBroadcast", "servo_id", 255, true, WriteCheck::kOutOfRange},
    // the range check wins over the dangerous check
    {"ServoId300NotArmed", "servo_id", 300, false, WriteCheck::kOutOfRange},
    {"BaudrateZero", "baudrate", 0, true, WriteCheck::kOutOfRange},
    {"BaudrateEight", "baudrate", 8, true, WriteCheck::kOutOfRange},
    {"Baudrate7Armed", "baudrate", 7, true, WriteCheck::kOk},
    {"Baudrate1NotArmed", "baudrate", 1, false, WriteCheck::kDangerous},
    // Datasheet ranges: stall_protect_mode 1 (limit power) or 2 (release); switches 0..1.
    {"StallModeZero", "stall_protect_mode", 0, false, WriteCheck::kOutOfRange},
    {"StallModeOne", "stall_protect_mode", 1, false, WriteCheck::kOk},
    {"StallModeTwo", "stall_protect_mode", 2, false, WriteCheck::kOk},
    {"StallModeThree", "stall_protect_mode", 3, false, WriteCheck::kOutOfRange},
    {"SwitchOne", "angle_limit_switch", 1, false, WriteCheck::kOk},
    {"SwitchTwo", "soft_start_switch", 2, false, WriteCheck::kOutOfRange},
    {"LockSwitchTwo", "po_lock_switch", 2, false, WriteCheck::kOutOfRange},
    {"U8Max", "reserved_35", 255, true, WriteCheck::kOk},
    {"U8Above", "reserved_35", 256, true, WriteCheck::kOutOfRange},
    {"U8Negative", "accel_switch", -1, false, WriteCheck::kOutOfRange},
    {"U16Max", "soft_start_time", 65535, false, WriteCheck::kOk},
    {"U16Above", "soft_start_time", 65536, false, WriteCheck::kOutOfRange},
    {"I16Min", "angle_limit_low", -32768, false, WriteCheck::kOk},
    {"I16BelowMin", "angle_limit_low", -32769, false, WriteCheck::kOutOfRange},
    {"I16AboveMax", "angle_mid_offset", 32768, false, WriteCheck::kOutOfRange},
};

class ServoParamsWriteCheck : public ::testing::TestWithParam<WriteCheckCase> {};

TEST_P(ServoParamsWriteCheck, Classified) {
  const WriteCheckCase& c = GetParam();
  const ParamInfo* param = findParam(c.name);
  ASSERT_NE(param, nullptr);
  EXPECT_EQ(checkWrite(*param, c.value, c.allow_dangerous), c.expected);
}

INSTANTIATE_TEST_SUITE_P(ServoParamsCases, ServoParamsWriteCheck, ::testing::ValuesIn(kWriteChecks),
                         [](const auto& info) { return info.param.label; });

TEST(ServoParams, DescribeReadOnly) {
  EXPECT_EQ(describe(WriteCheck::kReadOnly, *findParam("voltage"), 1),
            "parameter 'voltage' (id 1) is read-only");
}

TEST(ServoParams, DescribeOutOfRangeNamesValueRangeAndParameter) {
  EXPECT_EQ(describe(WriteCheck::kOutOfRange, *findParam("servo_id"), 300),
            "value 300 out of range 0..254 for parameter 'servo_id' (id 34)");
  EXPECT_EQ(describe(WriteCheck::kOutOfRange, *findParam("angle_limit_low"), -40000),
            "value -40000 out of range -32768..32767 for parameter 'angle_limit_low' (id 52)");
}

TEST(ServoParams, DescribeDangerousSaysWhy) {
  const std::string text = describe(WriteCheck::kDangerous, *findParam("baudrate"), 3);
  EXPECT_NE(text.find("'baudrate' (id 36)"), std::string::npos) << text;
  EXPECT_NE(text.find("unreachable"), std::string::npos) << text;
}

// --- value encoding ------------------------------------------------------------------------------

struct ReadValueCase {
  std::string label;
  const char* name;
  std::vector<uint8_t> bytes;
  int64_t value;
};

const ReadValueCase kReadValues[] = {
    {"U8", "servo_status", {0x07}, 7},
    {"U8High", "servo_id", {0xFE}, 254},
    {"U16", "voltage", {0x34, 0x12}, 0x1234},
    {"U16High", "over_power", {0xFF, 0xFF}, 65535},
    {"U32", "serial_number", {0x78, 0x56, 0x34, 0x12}, 0x12345678},
    {"U32High", "serial_number", {0x00, 0x00, 0x00, 0x80}, 0x80000000LL},
    {"I16Negative", "angle_mid_offset", {0x9C, 0xFF}, -100},
    {"I16Positive", "angle_limit_high", {0x84, 0x03}, 900},
    {"I16Min", "angle_limit_low", {0x00, 0x80}, -32768},
};

class ServoParamsReadValue : public ::testing::TestWithParam<ReadValueCase> {};

TEST_P(ServoParamsReadValue, LittleEndian) {
  const ReadValueCase& c = GetParam();
  const ParamInfo* param = findParam(c.name);
  ASSERT_NE(param, nullptr);
  const std::optional<int64_t> value = readValue(*param, c.bytes.data(), c.bytes.size());
  ASSERT_TRUE(value.has_value());
  EXPECT_EQ(*value, c.value);
}

TEST_P(ServoParamsReadValue, WriteValueProducesSameBytes) {
  const ReadValueCase& c = GetParam();
  const ParamInfo* param = findParam(c.name);
  ASSERT_NE(param, nullptr);
  uint8_t out[4] = {0xAA, 0xAA, 0xAA, 0xAA};
  ASSERT_EQ(writeValue(*param, c.value, out), c.bytes.size());
  EXPECT_EQ(std::vector<uint8_t>(out, out + c.bytes.size()), c.bytes);
}

INSTANTIATE_TEST_SUITE_P(ServoParamsCases, ServoParamsReadValue, ::testing::ValuesIn(kReadValues),
                         [](const auto& info) { return info.param.label; });

TEST(ServoParams, ReadValueRejectsWrongSize) {
  const uint8_t bytes[4] = {1, 2, 3, 4};
  EXPECT_FALSE(readValue(*findParam("voltage"), bytes, 1).has_value());
  EXPECT_FALSE(readValue(*findParam("servo_status"), bytes, 2).has_value());
  EXPECT_FALSE(readValue(*findParam("serial_number"), bytes, 2).has_value());
}

// --- user block layout ---------------------------------------------------------------------------

struct OffsetCase {
  int data_id;
  std::size_t offset;
};

// u8 = 1 byte, u16/i16 = 2 bytes, packed in id order from 32.
const OffsetCase kOffsets[] = {
    {32, 0},  {33, 1},  {34, 2},  {35, 3},  {36, 4},  {37, 5},  {38, 6},  {39, 8},
    {40, 10}, {41, 12}, {42, 14}, {43, 16}, {44, 18}, {45, 19}, {46, 20}, {47, 21},
    {48, 22}, {49, 23}, {50, 24}, {51, 26}, {52, 28}, {53, 30},
};

class ServoParamsUserBlock : public ::testing::TestWithParam<OffsetCase> {};

TEST_P(ServoParamsUserBlock, Offset) {
  const ParamInfo* param = findParamById(static_cast<uint8_t>(GetParam().data_id));
  ASSERT_NE(param, nullptr);
  const std::optional<std::size_t> offset = userBlockOffset(*param);
  ASSERT_TRUE(offset.has_value());
  EXPECT_EQ(*offset, GetParam().offset);
  EXPECT_LE(*offset + typeSize(param->type), kUserBlockSize);
}

INSTANTIATE_TEST_SUITE_P(ServoParamsAllUserParams, ServoParamsUserBlock,
                         ::testing::ValuesIn(kOffsets),
                         [](const auto& info) { return std::to_string(info.param.data_id); });

TEST(ServoParams, UserBlockIsExactly32Bytes) {
  const ParamInfo* last = findParamById(kLastUserParamId);
  ASSERT_NE(last, nullptr);
  EXPECT_EQ(*userBlockOffset(*last) + typeSize(last->type), kUserBlockSize);
}

TEST(ServoParams, ReadOnlyParamsHaveNoUserBlockOffset) {
  for (const ParamInfo& param : paramTable()) {
    EXPECT_EQ(userBlockOffset(param).has_value(), !param.read_only) << param.name;
  }
}

TEST(ServoParams, UserBlockPacksEveryReadWriteParamAndUnpacksToTheSameValues) {
  // A value per parameter that fits its type and tells the parameters apart.
  const auto value_of = [](const ParamInfo& param) {
    return param.type == ParamType::kI16 ? -int64_t{param.data_id} : int64_t{param.data_id};
  };
  const std::array<uint8_t, kUserBlockSize> block = packUserBlock(value_of);
  EXPECT_EQ(block[0], 32);  // reserved_32 first, u8
  EXPECT_EQ(block[6], 38);  // stall_power_limit, u16 little-endian
  EXPECT_EQ(block[7], 0);
  EXPECT_EQ(block[30], 0xCB);  // angle_mid_offset -53 = 0xFFCB
  EXPECT_EQ(block[31], 0xFF);
  const auto values = unpackUserBlock(block);
  ASSERT_EQ(values.size(), std::size(kOffsets));
  for (const auto& [param, value] : values) EXPECT_EQ(value, value_of(*param)) << param->name;
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
