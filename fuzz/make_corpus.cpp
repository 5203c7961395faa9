// Writes the fuzz targets' seed corpora through the codecs' own encoders, so that no seed spells a
// frame's bytes by hand: one seed per servo command (request and answer) and per base / body frame
// kind, plus a few streams that mix them. The golden vectors of docs/protocols.md stay in the unit
// tests, which check these same encoders against them.
//
//   make_corpus OUT_DIR
//     OUT_DIR/fuzz_framer/    3-byte prefix (families, servo count, max chunk) + byte stream
//     OUT_DIR/fuzz_decoders/  1-byte selector (family index + families * mode), servo count, frame
// (the input layouts of fuzz_framer.cpp and fuzz_decoders.cpp).
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "registered_families.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_params.h"

namespace {

namespace base = serial_robot_driver::devices::base;
namespace body = serial_robot_driver::devices::body;
namespace servo_bus = serial_robot_driver::devices::servo_bus;
using Bytes = std::vector<uint8_t>;

Bytes join(std::initializer_list<Bytes> parts) {
  Bytes all;
  for (const Bytes& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

class SeedWriter {
 public:
  explicit SeedWriter(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::filesystem::create_directories(dir_);
  }
  void write(const std::string& name, const Bytes& prefix, const Bytes& frames) {
    const Bytes seed = join({prefix, frames});
    std::ofstream out(dir_ / name, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(seed.data()),
              static_cast<std::streamsize>(seed.size()));
    ++count_;
  }
  int count() const { return count_; }

 private:
  std::filesystem::path dir_;
  int count_ = 0;
};

// --- base --------------------------------------------------------------------------------------
const Bytes kBaseReset = base::encodeReset(2);
const Bytes kBaseBatteryRequest = base::encodeBatteryRequest(1);
const Bytes kBaseClearEncoders = base::encodeClearEncoders(3);
const Bytes kBaseLeft4 = base::encodeWheelSpeed(0, 4, 0);
const Bytes kBaseBothMinus6 = base::encodeWheelSpeed(0, -6, -6);
const Bytes kBaseBatteryReply = base::encodeBatteryReply(7, 100);
const Bytes kBaseErrorStatus = base::encodeErrorStatus(8);

// --- body --------------------------------------------------------------------------------------
body::Telemetry telemetry(bool with_foot) {
  body::Telemetry frame;
  frame.servo_count = 2;
  frame.servos[0] = {2048, 10};
  frame.servos[1] = {1024, -5};
  frame.imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  frame.has_foot = with_foot;
  for (std::size_t j = 0; j < body::kFootSensorCount; ++j) {
    frame.foot[j] = static_cast<uint16_t>(j + 1);
  }
  return frame;
}
const Bytes kTelemetry = body::encodeTelemetry(telemetry(false));
const Bytes kTelemetryFoot = body::encodeTelemetry(telemetry(true));
const Bytes kSyncWrite = body::encodeSyncWrite({{2, 2048}, {3, 1024}});

// A Dynamixel 2.0 PING to id 1: a frame with a valid CRC that is not our sync write.
Bytes dynamixelPing() {
  constexpr uint8_t kPingInstruction = 0x01;
  constexpr uint16_t kPingLen = 1 + body::kCrcSize;
  Bytes frame(body::kSyncWriteHeader.begin(), body::kSyncWriteHeader.end());
  frame.push_back(1);
  frame.push_back(static_cast<uint8_t>(kPingLen));
  frame.push_back(static_cast<uint8_t>(kPingLen >> 8));
  frame.push_back(kPingInstruction);
  const uint16_t crc = body::dynamixelCrc(frame.data(), frame.size());
  frame.push_back(static_cast<uint8_t>(crc));
  frame.push_back(static_cast<uint8_t>(crc >> 8));
  return frame;
}

// --- servo bus: one request and one answer per command ------------------------------------------
const servo_bus::ParamInfo& param(const char* name) { return *servo_bus::findParam(name); }

servo_bus::MoveRamps ramps(uint16_t accel_ms, uint16_t decel_ms) {
  servo_bus::MoveRamps result;
  result.accel_ms = accel_ms;
  result.decel_ms = decel_ms;
  return result;
}

std::array<uint8_t, servo_bus::kUserBlockSize> userBlock() {
  std::array<uint8_t, servo_bus::kUserBlockSize> block{};
  for (const servo_bus::ParamInfo& info : servo_bus::paramTable()) {
    if (const auto offset = servo_bus::userBlockOffset(info)) {
      servo_bus::writeValue(info, info.min + (info.max - info.min) / 2, &block[*offset]);
    }
  }
  return block;
}

Bytes request(servo_bus::Command cmd) {
  using servo_bus::Command;
  switch (cmd) {
    case Command::kPing:
      return servo_bus::encodePing(3);
    case Command::kResetUserData:
      return servo_bus::encodeResetUserData(3);
    case Command::kReadData:
      return servo_bus::encodeReadData(3, param("voltage").data_id);
    case Command::kWriteData:
      return servo_bus::encodeWriteData(3, param("angle_limit_low"), -900);
    case Command::kReadBatchData:
      return servo_bus::encodeReadBatchData(3);
    case Command::kWriteBatchData:
      return servo_bus::encodeWriteBatchData(3, userBlock());
    case Command::kSpin:
      return servo_bus::encodeSpin(0, true, servo_bus::SpinMode::kDurationMs, 100, 1000);
    case Command::kRotate:
      return servo_bus::encodeRotate(2, 900, 500, 0);
    case Command::kDamping:
      return servo_bus::encodeDamping(0, 500);
    case Command::kReadAngle:
      return servo_bus::encodeReadAngle(0);
    case Command::kMoveByInterval:
      return servo_bus::encodeMoveByInterval(1, 900, 1000, ramps(100, 100));
    case Command::kMoveByVelocity:
      return servo_bus::encodeMoveByVelocity(1, -900, 3600, ramps(100, 100));
    case Command::kMultiTurnMove:
      return servo_bus::encodeMultiTurnMove(1, 7200, 2000, 0);
    case Command::kMultiTurnMoveByInterval:
      return servo_bus::encodeMultiTurnMoveByInterval(1, -3600, 1000, ramps(200, 200));
    case Command::kMultiTurnMoveByVelocity:
      return servo_bus::encodeMultiTurnMoveByVelocity(1, 36000, 3600, ramps(100, 100));
    case Command::kReadMultiTurnAngle:
      return servo_bus::encodeReadMultiTurnAngle(1);
  }
  return {};
}

Bytes answerContent(servo_bus::Command cmd) {
  using servo_bus::Command;
  switch (cmd) {
    case Command::kPing:
      return servo_bus::pingAnswerContent(3);
    case Command::kReadData:
      return servo_bus::readDataAnswerContent(3, param("voltage"), 7400);
    case Command::kWriteData:
      return servo_bus::writeDataAnswerContent(3, param("angle_limit_low").data_id, true);
    case Command::kReadBatchData:
      return servo_bus::userBlockAnswerContent(3, userBlock());
    case Command::kReadAngle:
      return servo_bus::angleAnswerContent({0, 902});
    case Command::kReadMultiTurnAngle:
      return servo_bus::multiTurnAngleContent({1, 7200, 2});
    default:  // every other command answers with a result byte (see the command table)
      return servo_bus::resultAnswerContent(1, true);
  }
}

Bytes answer(servo_bus::Command cmd) { return servo_bus::encodeResponse(cmd, answerContent(cmd)); }

// "MULTI_TURN_MOVE_BY_INTERVAL (CMD 14)" -> "multi_turn_move_by_interval"
std::string seedName(const char* command_name) {
  std::string name;
  for (const char* c = command_name; *c != '\0' && *c != ' '; ++c) {
    name.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(*c))));
  }
  return name;
}

// Selector bytes of fuzz_decoders.cpp: the family's index + families * mode (0 raw, 1 fix sum,
// 2 fix all), from the registered families, as the fuzzer reads them.
uint8_t selector(const char* family, std::size_t mode) {
  return fuzz_support::decoderSelector(family, mode);
}
constexpr std::size_t kRaw = 0, kFixSum = 1, kFixAll = 2;

void writeFramerSeeds(SeedWriter& seeds) {
  // Prefix bits of fuzz_framer.cpp: one per registered family (registered_families.h); asked
  // here, not at static initialisation, where the device modules may not be built yet.
  const uint8_t kBaseBit = fuzz_support::familyBit("base");
  const uint8_t kTelemetryBit = fuzz_support::familyBit("telemetry");
  const uint8_t kResponseBit = fuzz_support::familyBit("servo_response");
  const uint8_t kRequestBit = fuzz_support::familyBit("servo_request");
  const uint8_t kSyncWriteBit = fuzz_support::familyBit("sync_write");
  constexpr uint8_t kResetBit = 0x80;
  const uint8_t kAllFamilies =
      static_cast<uint8_t>(kBaseBit | kTelemetryBit | kResponseBit | kRequestBit | kSyncWriteBit);
  const Bytes all = {kAllFamilies, 2, 0};  // one feed
  seeds.write("base_reset", all, kBaseReset);
  seeds.write("base_wheels", all, join({kBaseLeft4, kBaseBothMinus6}));
  seeds.write("base_replies", {kBaseBit, 0, 0}, join({kBaseBatteryReply, kBaseErrorStatus}));
  seeds.write("telemetry", all, kTelemetry);
  seeds.write("telemetry_foot_chunked", {kTelemetryBit, 2, 5}, join({kTelemetryFoot, kTelemetry}));
  seeds.write("sync_write", all, kSyncWrite);
  seeds.write(
      "simulator_input", {static_cast<uint8_t>(kBaseBit | kRequestBit | kSyncWriteBit), 0, 4},
      join({dynamixelPing(), kSyncWrite, request(servo_bus::Command::kRotate), kBaseReset}));
  Bytes requests, answers;
  for (const servo_bus::CommandInfo& info : servo_bus::commandTable()) {
    requests = join({requests, request(info.cmd)});
    answers = join({answers, answer(info.cmd)});
  }
  seeds.write("servo_requests", all, requests);
  seeds.write("servo_responses", {static_cast<uint8_t>(kResponseBit | kRequestBit), 2, 1}, answers);
  const Bytes junk = {0x00, base::kHeader0, servo_bus::kRequestHeader0};
  seeds.write("driver_mixed_with_junk",
              {static_cast<uint8_t>(kBaseBit | kTelemetryBit | kResponseBit | kRequestBit), 2, 7},
              join({junk,
                    kTelemetry,
                    {servo_bus::kResponseHeader0},
                    kBaseBatteryReply,
                    {body::kSyncWriteHeader[0], body::kSyncWriteHeader[1]},
                    request(servo_bus::Command::kReadAngle),
                    answer(servo_bus::Command::kReadAngle),
                    {body::kTelemetryHeader0, body::kTelemetryHeader1},
                    kTelemetryFoot,
                    kBaseErrorStatus}));
  seeds.write("everything_reset", {static_cast<uint8_t>(kAllFamilies | kResetBit), 2, 3},
              join({kTelemetry, kSyncWrite, kBaseClearEncoders, answer(servo_bus::Command::kPing),
                    kBaseBatteryRequest, kTelemetryFoot}));
}

void writeDecoderSeeds(SeedWriter& seeds) {
  seeds.write("base_reset_raw", {selector("base", kRaw), 2}, kBaseReset);
  seeds.write("base_battery_request_raw", {selector("base", kRaw), 2}, kBaseBatteryRequest);
  seeds.write("base_clear_encoders_raw", {selector("base", kRaw), 2}, kBaseClearEncoders);
  seeds.write("base_wheels_raw", {selector("base", kRaw), 2}, kBaseBothMinus6);
  seeds.write("base_error_status_raw", {selector("base", kRaw), 2}, kBaseErrorStatus);
  seeds.write("base_battery_fixsum", {selector("base", kFixSum), 2}, kBaseBatteryReply);
  seeds.write("base_fixall", {selector("base", kFixAll), 2}, kBaseLeft4);
  seeds.write("telemetry_raw", {selector("telemetry", kRaw), 2}, kTelemetry);
  seeds.write("telemetry_foot_raw", {selector("telemetry", kRaw), 2}, kTelemetryFoot);
  seeds.write("telemetry_fixsum", {selector("telemetry", kFixSum), 2}, kTelemetry);
  seeds.write("telemetry_fixall", {selector("telemetry", kFixAll), 6}, kTelemetryFoot);
  for (const servo_bus::CommandInfo& info : servo_bus::commandTable()) {
    const std::string name = seedName(info.name);
    seeds.write("servo_request_" + name + "_raw", {selector("servo_request", kRaw), 0},
                request(info.cmd));
    seeds.write("servo_answer_" + name + "_raw", {selector("servo_response", kRaw), 0},
                answer(info.cmd));
  }
  seeds.write("servo_request_fixsum", {selector("servo_request", kFixSum), 0},
              request(servo_bus::Command::kSpin));
  seeds.write("servo_response_fixsum", {selector("servo_response", kFixSum), 0},
              answer(servo_bus::Command::kPing));
  seeds.write("servo_read_data_fixall", {selector("servo_response", kFixAll), 0},
              answer(servo_bus::Command::kReadData));
  seeds.write("servo_read_batch_fixall", {selector("servo_response", kFixAll), 0},
              answer(servo_bus::Command::kReadBatchData));
  seeds.write("sync_write_raw", {selector("sync_write", kRaw), 0}, kSyncWrite);
  seeds.write("sync_write_fixcrc", {selector("sync_write", kFixSum), 0}, kSyncWrite);
  // Three bytes more: with the fix-ups they become a third servo record.
  seeds.write("sync_write_fixall", {selector("sync_write", kFixAll), 0},
              join({kSyncWrite, {5, 0, 8}}));
  seeds.write("dynamixel_ping_raw", {selector("sync_write", kRaw), 0}, dynamixelPing());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path out = argv[1];
  SeedWriter framer(out / "fuzz_framer");
  SeedWriter decoders(out / "fuzz_decoders");
  writeFramerSeeds(framer);
  writeDecoderSeeds(decoders);
  std::printf("corpus written to %s (%d framer seeds, %d decoder seeds)\n", out.c_str(),
              framer.count(), decoders.count());
  return 0;
}
