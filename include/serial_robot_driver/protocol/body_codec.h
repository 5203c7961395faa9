// Servo controller board protocol (docs/protocols.md, section 2).
//
// Host -> board: Dynamixel 2.0 Sync Write of goal positions, CRC-16/BUYPASS (Boost.CRC):
//   FF FF FD 00 | FE | LEN_L LEN_H | 83 | 74 00 | 02 00 | (ID, POS_L, POS_H) x N | CRC_L CRC_H
// Board -> host: telemetry, big-endian except the foot block:
//   12 34 | LEN | servo block (4N) | IMU block (18) | [foot block (16, little-endian)] | SUM | 1F 2F
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/protocol/decode_result.h"
#include "serial_robot_driver/protocol/frame_family.h"

namespace serial_robot_driver::protocol::body {

// --- sync write --------------------------------------------------------------------------------
constexpr std::array<uint8_t, 4> kSyncWriteHeader = {0xFF, 0xFF, 0xFD, 0x00};
constexpr uint8_t kBroadcastId = 0xFE;
constexpr uint8_t kSyncWriteInstruction = 0x83;
constexpr uint16_t kGoalPositionAddress = 0x0074;
constexpr uint16_t kGoalPositionSize = 2;
/// Bytes before the LEN field counts start: header (4) + id (1) + LEN (2).
constexpr std::size_t kSyncWritePrefix = 7;
/// LEN = instruction + address + size + 3N + CRC = 7 + 3N.
constexpr std::size_t syncWriteLen(std::size_t servo_count) { return 7 + 3 * servo_count; }
/// The largest sync write we build or accept (ids are 0..253 without broadcast).
constexpr std::size_t kMaxSyncWriteServos = 64;

/// CRC-16/BUYPASS as used by Dynamixel 2.0 (poly 0x8005, init 0, no reflection, no final XOR).
uint16_t dynamixelCrc(const uint8_t* data, std::size_t size);

struct ServoTarget {
  uint8_t id = 0;
  uint16_t position = 0;  ///< raw ticks
};

std::vector<uint8_t> encodeSyncWrite(const std::vector<ServoTarget>& targets);
/// Probes for a complete sync write: header and broadcast id, LEN (7 + 3N, N <= 64),
/// instruction, CRC (kBadHeader / kBadLength / kBadChecksum).
Probe probeSyncWrite(const uint8_t* data, std::size_t available);
/// Sync writes (host -> board; what the simulated board reads): "sync_write".
extern const FrameFamily kSyncWriteFrames;
/// For the simulator: a complete sync-write frame back into targets (CRC and layout checked).
Decoded<std::vector<ServoTarget>> decodeSyncWrite(const uint8_t* data, std::size_t size);

// --- telemetry ---------------------------------------------------------------------------------
constexpr uint8_t kTelemetryHeader0 = 0x12;
constexpr uint8_t kTelemetryHeader1 = 0x34;
constexpr uint8_t kTelemetryTail0 = 0x1F;
constexpr uint8_t kTelemetryTail1 = 0x2F;
constexpr std::size_t kImuValueCount = 9;
constexpr std::size_t kFootSensorCount = 8;
/// LEN = 24 + 4N without the foot block and 40 + 4N with it; LEN is one byte, so N <= 57.
constexpr std::size_t kMaxTelemetryServos = 57;
constexpr std::size_t telemetryLen(std::size_t servo_count, bool with_foot) {
  return 24 + 4 * servo_count + (with_foot ? 16 : 0);
}

/// Indices into Telemetry::imu (assumption of docs/protocols.md: accel, gyro, attitude).
enum ImuIndex : std::size_t {
  kAccelX = 0, kAccelY, kAccelZ, kGyroX, kGyroY, kGyroZ, kRoll, kPitch, kYaw
};

struct ServoSample {
  uint16_t position = 0;  ///< raw ticks
  int16_t speed = 0;      ///< raw, signed two's complement (assumption)
};

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

/// Probes for a complete telemetry frame of `servo_count` servos: header, LEN (24 + 4N or 40 + 4N),
/// then tail before SUM (kBadHeader / kBadLength / kBadTail / kBadChecksum).
Probe probeTelemetry(const uint8_t* data, std::size_t available, std::size_t servo_count);
/// Telemetry (board -> host): "telemetry"; the framer's argument is the servo count.
extern const FrameFamily kTelemetryFrames;

/// Decodes one complete telemetry frame for `servo_count` configured servos. LEN must be
/// telemetryLen(servo_count, false|true) and match `size`.
Decoded<Telemetry> decodeTelemetry(const uint8_t* data, std::size_t size, std::size_t servo_count);

/// For the simulator and benchmarks.
std::vector<uint8_t> encodeTelemetry(const Telemetry& telemetry);

}  // namespace serial_robot_driver::protocol::body
