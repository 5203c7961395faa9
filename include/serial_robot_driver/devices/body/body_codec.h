// Servo controller board protocol (docs/protocols.md, section 2).
//
// Host -> board: Dynamixel 2.0 Sync Write of goal positions, CRC-16/BUYPASS (Boost.CRC):
//   header | id | LEN | command fields | servo record x N | CRC
// Board -> host: telemetry:
//   header | LEN | servo record x N | IMU values | [foot values] | SUM | tail
// The records and values are the field lists below; the envelopes' constants are next to them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/protocol/decode_result.h"
#include "serial_robot_driver/protocol/frame_family.h"
#include "serial_robot_driver/protocol/wire_fields.h"

namespace serial_robot_driver::devices::body {

// --- sync write --------------------------------------------------------------------------------
constexpr std::array<uint8_t, 4> kSyncWriteHeader = {0xFF, 0xFF, 0xFD, 0x00};
constexpr uint8_t kBroadcastId = 0xFE;
constexpr uint8_t kSyncWriteInstruction = 0x83;
constexpr uint16_t kGoalPositionAddress = 0x0074;
constexpr uint16_t kGoalPositionSize = 2;
/// Bytes before the LEN field counts start: header (4) + id (1) + LEN (2).
constexpr std::size_t kSyncWritePrefix = 7;
/// The largest sync write we build or accept (ids are 0..253 without broadcast).
constexpr std::size_t kMaxSyncWriteServos = 64;

/// CRC-16/BUYPASS as used by Dynamixel 2.0 (poly 0x8005, init 0, no reflection, no final XOR).
uint16_t dynamixelCrc(const uint8_t* data, std::size_t size);
constexpr std::size_t kCrcSize = 2;

/// The fields LEN counts before the servo records.
struct SyncWriteCommand {
  uint8_t instruction = kSyncWriteInstruction;
  uint16_t address = kGoalPositionAddress;
  uint16_t data_size = kGoalPositionSize;
};
constexpr std::array<protocol::wire::Field<SyncWriteCommand>, 3> kSyncWriteCommandFields = {{
    protocol::wire::field<&SyncWriteCommand::instruction>("instruction", protocol::wire::kU8,
                                                          protocol::wire::ByteOrder::kLittle),
    protocol::wire::field<&SyncWriteCommand::address>("address", protocol::wire::kU16,
                                                      protocol::wire::ByteOrder::kLittle),
    protocol::wire::field<&SyncWriteCommand::data_size>("data_size", protocol::wire::kU16,
                                                        protocol::wire::ByteOrder::kLittle),
}};

struct ServoTarget {
  uint8_t id = 0;
  uint16_t position = 0;  ///< raw ticks
};
constexpr std::array<protocol::wire::Field<ServoTarget>, 2> kServoTargetFields = {{
    protocol::wire::field<&ServoTarget::id>("id", protocol::wire::kU8,
                                            protocol::wire::ByteOrder::kLittle),
    protocol::wire::field<&ServoTarget::position>("position", protocol::wire::kU16,
                                                  protocol::wire::ByteOrder::kLittle, "ticks"),
}};

/// LEN: the command fields, one record per servo, the CRC.
constexpr std::size_t syncWriteLen(std::size_t servo_count) {
  return protocol::wire::listOf(kSyncWriteCommandFields).size() +
         protocol::wire::listOf(kServoTargetFields).size() * servo_count + kCrcSize;
}

std::vector<uint8_t> encodeSyncWrite(const std::vector<ServoTarget>& targets);
/// Probes for a complete sync write: header and broadcast id, LEN (syncWriteLen, N <= 64),
/// instruction, CRC (kBadHeader / kBadLength / kBadChecksum).
protocol::Probe probeSyncWrite(const uint8_t* data, std::size_t available);
/// Sync writes (host -> board; what the simulated board reads): "sync_write".
extern const protocol::FrameFamily kSyncWriteFrames;
/// For the simulator: a complete sync-write frame back into targets (CRC and layout checked).
protocol::Decoded<std::vector<ServoTarget>> decodeSyncWrite(const uint8_t* data, std::size_t size);

// --- telemetry ---------------------------------------------------------------------------------
constexpr uint8_t kTelemetryHeader0 = 0x12;
constexpr uint8_t kTelemetryHeader1 = 0x34;
constexpr uint8_t kTelemetryTail0 = 0x1F;
constexpr uint8_t kTelemetryTail1 = 0x2F;
constexpr std::size_t kImuValueCount = 9;
constexpr std::size_t kFootSensorCount = 8;

/// Indices into Telemetry::imu (assumption of docs/protocols.md: accel, gyro, attitude).
enum ImuIndex : std::size_t {
  kAccelX = 0,
  kAccelY,
  kAccelZ,
  kGyroX,
  kGyroY,
  kGyroZ,
  kRoll,
  kPitch,
  kYaw
};

struct ServoSample {
  uint16_t position = 0;  ///< raw ticks
  int16_t speed = 0;      ///< raw, signed two's complement (assumption)
};

// The blocks of a telemetry frame, one field list each: a servo record (N of them), an IMU value
// (kImuValueCount) and a foot sensor (kFootSensorCount, the only little-endian block).
constexpr std::array<protocol::wire::Field<ServoSample>, 2> kServoSampleFields = {{
    protocol::wire::field<&ServoSample::position>("position", protocol::wire::kU16,
                                                  protocol::wire::ByteOrder::kBig, "ticks"),
    protocol::wire::field<&ServoSample::speed>("speed", protocol::wire::kI16,
                                               protocol::wire::ByteOrder::kBig),
}};
struct TelemetryValue {
  int64_t value = 0;
};
constexpr protocol::wire::Field<TelemetryValue> kImuValueField =
    protocol::wire::field<&TelemetryValue::value>("imu", protocol::wire::kI16,
                                                  protocol::wire::ByteOrder::kBig);
constexpr protocol::wire::Field<TelemetryValue> kFootValueField =
    protocol::wire::field<&TelemetryValue::value>("foot", protocol::wire::kU16,
                                                  protocol::wire::ByteOrder::kLittle);
/// Bytes around the blocks: header (2) + LEN before them, SUM + tail (2) after them.
constexpr std::size_t kTelemetryPrefix = 3;
constexpr std::size_t kTelemetryTrailer = 3;
constexpr std::size_t kImuBlockSize = kImuValueField.type.width * kImuValueCount;
constexpr std::size_t kFootBlockSize = kFootValueField.type.width * kFootSensorCount;

/// LEN is the whole frame; one byte, so at most kMaxTelemetryServos servos.
constexpr std::size_t telemetryLen(std::size_t servo_count, bool with_foot) {
  return kTelemetryPrefix + protocol::wire::listOf(kServoSampleFields).size() * servo_count +
         kImuBlockSize + (with_foot ? kFootBlockSize : 0) + kTelemetryTrailer;
}
constexpr std::size_t kMaxTelemetryServos = 57;
static_assert(telemetryLen(kMaxTelemetryServos, false) <= 255 &&
                  telemetryLen(kMaxTelemetryServos + 1, false) > 255,
              "LEN is one byte");

/// One decoded telemetry frame in raw units. Fixed-size storage: decoding never allocates.
struct Telemetry {
  std::size_t servo_count = 0;
  std::array<ServoSample, kMaxTelemetryServos> servos{};
  std::array<int16_t, kImuValueCount> imu{};
  bool has_foot = false;
  std::array<uint16_t, kFootSensorCount> foot{};
};

/// SUM byte: (sum of bytes 2 .. LEN-4) mod 256 of a frame whose LEN byte is already in place.
uint8_t telemetrySum(const uint8_t* frame, std::size_t len);

/// Probes for a complete telemetry frame of `servo_count` servos: header, LEN (telemetryLen),
/// then tail before SUM (kBadHeader / kBadLength / kBadTail / kBadChecksum).
protocol::Probe probeTelemetry(const uint8_t* data, std::size_t available, std::size_t servo_count);
/// Telemetry (board -> host): "telemetry"; the framer's argument is the servo count.
extern const protocol::FrameFamily kTelemetryFrames;

/// Decodes one complete telemetry frame for `servo_count` configured servos. LEN must be
/// telemetryLen(servo_count, false|true) and match `size`.
protocol::Decoded<Telemetry> decodeTelemetry(const uint8_t* data, std::size_t size,
                                             std::size_t servo_count);

/// For the simulator and benchmarks.
std::vector<uint8_t> encodeTelemetry(const Telemetry& telemetry);

}  // namespace serial_robot_driver::devices::body
