#include "serial_robot_driver/protocol/body_codec.h"

#include <algorithm>
#include "serial_robot_driver/protocol/stream_framer.h"
#include <boost/crc.hpp>

#include "serial_robot_driver/protocol/byte_order.h"

namespace serial_robot_driver::protocol::body {

namespace {

// Sync write layout: header(4) id(1) LEN(2) instruction(1) address(2) size(2) data(3N) crc(2).
constexpr std::size_t kIdOffset = 4;
constexpr std::size_t kLenOffset = 5;
constexpr std::size_t kInstructionOffset = 7;
constexpr std::size_t kAddressOffset = 8;
constexpr std::size_t kDataSizeOffset = 10;
constexpr std::size_t kFirstTargetOffset = 12;
constexpr std::size_t kBytesPerTarget = 3;
constexpr std::size_t kCrcSize = 2;
constexpr std::size_t kMinSyncWriteLen = syncWriteLen(0);

// Telemetry layout: header(2) LEN(1) servos(4N) imu(18) [foot(16)] SUM(1) tail(2).
constexpr std::size_t kTelemetryLenOffset = 2;
constexpr std::size_t kTelemetryServoOffset = 3;
constexpr std::size_t kBytesPerServo = 4;
constexpr std::size_t kTelemetryTrailer = 3;   // SUM + tail
constexpr std::size_t kMaxTelemetryLen = 255;  // LEN is one byte

std::size_t imuOffset(std::size_t servo_count) {
  return kTelemetryServoOffset + kBytesPerServo * servo_count;
}
std::size_t footOffset(std::size_t servo_count) {
  return imuOffset(servo_count) + 2 * kImuValueCount;
}

}  // namespace

uint16_t dynamixelCrc(const uint8_t* data, std::size_t size) {
  boost::crc_optimal<16, 0x8005, 0, 0, false, false> crc;
  crc.process_bytes(data, size);
  return crc.checksum();
}

std::vector<uint8_t> encodeSyncWrite(const std::vector<ServoTarget>& targets) {
  // More targets than ids can exist is a caller bug; an empty result sends nothing.
  if (targets.size() > kMaxSyncWriteServos) return {};
  std::vector<uint8_t> frame(kSyncWritePrefix + syncWriteLen(targets.size()));
  std::copy(kSyncWriteHeader.begin(), kSyncWriteHeader.end(), frame.begin());
  frame[kIdOffset] = kBroadcastId;
  writeLE16(&frame[kLenOffset], static_cast<uint16_t>(syncWriteLen(targets.size())));
  frame[kInstructionOffset] = kSyncWriteInstruction;
  writeLE16(&frame[kAddressOffset], kGoalPositionAddress);
  writeLE16(&frame[kDataSizeOffset], kGoalPositionSize);
  std::size_t pos = kFirstTargetOffset;
  for (const ServoTarget& target : targets) {
    frame[pos] = target.id;
    writeLE16(&frame[pos + 1], target.position);
    pos += kBytesPerTarget;
  }
  writeLE16(&frame[pos], dynamixelCrc(frame.data(), pos));
  return frame;
}

Probe probeSyncWrite(const uint8_t* data, std::size_t available) {
  // FF FF FD 00 then the broadcast id FE: compare as much of this prefix as has arrived.
  const std::size_t header_size = kSyncWriteHeader.size();
  const std::size_t known = std::min(available, header_size + 1);
  for (std::size_t i = 0; i < known; ++i) {
    const uint8_t expected = i < header_size ? kSyncWriteHeader[i] : kBroadcastId;
    if (data[i] != expected) return Probe::invalid(DecodeError::kBadHeader);
  }
  if (available < kSyncWritePrefix) return Probe::needMore();
  const std::size_t len = readLE16(data + kLenOffset);
  if (len < kMinSyncWriteLen || (len - kMinSyncWriteLen) % kBytesPerTarget != 0 ||
      (len - kMinSyncWriteLen) / kBytesPerTarget > kMaxSyncWriteServos) {
    return Probe::invalid(DecodeError::kBadLength);
  }
  if (available <= kInstructionOffset) return Probe::needMore();
  // Another Dynamixel instruction is not a frame of ours; not counted as an error.
  if (data[kInstructionOffset] != kSyncWriteInstruction) {
    return Probe::invalid(DecodeError::kBadHeader);
  }
  const std::size_t size = kSyncWritePrefix + len;
  if (available < size) return Probe::needMore();
  if (dynamixelCrc(data, size - kCrcSize) != readLE16(data + size - kCrcSize)) {
    return Probe::invalid(DecodeError::kBadChecksum);
  }
  return Probe::frame(size);
}

Decoded<std::vector<ServoTarget>> decodeSyncWrite(const uint8_t* data, std::size_t size) {
  if (size < kSyncWritePrefix) return DecodeError::kTooShort;
  if (!std::equal(kSyncWriteHeader.begin(), kSyncWriteHeader.end(), data)) {
    return DecodeError::kBadHeader;
  }
  const std::size_t len = readLE16(&data[kLenOffset]);
  if (len < kMinSyncWriteLen || (len - kMinSyncWriteLen) % kBytesPerTarget != 0) {
    return DecodeError::kBadLength;
  }
  const std::size_t servo_count = (len - kMinSyncWriteLen) / kBytesPerTarget;
  if (servo_count > kMaxSyncWriteServos) return DecodeError::kBadLength;
  if (size < kSyncWritePrefix + len) return DecodeError::kTooShort;
  if (size > kSyncWritePrefix + len) return DecodeError::kBadLength;
  if (dynamixelCrc(data, size - kCrcSize) != readLE16(&data[size - kCrcSize])) {
    return DecodeError::kBadChecksum;
  }
  // A valid Dynamixel frame, but not the goal-position sync write we speak.
  if (data[kIdOffset] != kBroadcastId || data[kInstructionOffset] != kSyncWriteInstruction ||
      readLE16(&data[kAddressOffset]) != kGoalPositionAddress ||
      readLE16(&data[kDataSizeOffset]) != kGoalPositionSize) {
    return DecodeError::kUnexpectedContent;
  }

  std::vector<ServoTarget> targets(servo_count);
  for (std::size_t i = 0; i < servo_count; ++i) {
    const uint8_t* entry = &data[kFirstTargetOffset + kBytesPerTarget * i];
    targets[i].id = entry[0];
    targets[i].position = readLE16(&entry[1]);
  }
  return targets;
}

uint8_t telemetrySum(const uint8_t* frame, std::size_t len) {
  uint8_t sum = 0;
  for (std::size_t i = kTelemetryLenOffset; i + kTelemetryTrailer < len; ++i) {
    sum = static_cast<uint8_t>(sum + frame[i]);
  }
  return sum;
}

Probe probeTelemetry(const uint8_t* data, std::size_t available, std::size_t servo_count) {
  if (available < 1) return Probe::needMore();
  if (data[0] != kTelemetryHeader0) return Probe::invalid(DecodeError::kBadHeader);
  if (available < 2) return Probe::needMore();
  if (data[1] != kTelemetryHeader1) return Probe::invalid(DecodeError::kBadHeader);
  if (available <= kTelemetryLenOffset) return Probe::needMore();
  const std::size_t len = data[kTelemetryLenOffset];
  if (len != telemetryLen(servo_count, false) && len != telemetryLen(servo_count, true)) {
    return Probe::invalid(DecodeError::kBadLength);
  }
  if (available < len) return Probe::needMore();
  // Tail first: a wrong tail means the frame boundary itself is wrong.
  if (data[len - 2] != kTelemetryTail0 || data[len - 1] != kTelemetryTail1) {
    return Probe::invalid(DecodeError::kBadTail);
  }
  if (telemetrySum(data, len) != data[len - kTelemetryTrailer]) {
    return Probe::invalid(DecodeError::kBadChecksum);
  }
  return Probe::frame(len);
}

Decoded<Telemetry> decodeTelemetry(const uint8_t* data, std::size_t size, std::size_t servo_count) {
  if (servo_count > kMaxTelemetryServos) return DecodeError::kBadLength;
  if (size < kTelemetryLenOffset + 1) return DecodeError::kTooShort;
  if (data[0] != kTelemetryHeader0 || data[1] != kTelemetryHeader1) return DecodeError::kBadHeader;

  // N is configuration: LEN alone cannot tell 4 more servos from the 16-byte foot block.
  const std::size_t len = data[kTelemetryLenOffset];
  const bool has_foot = len == telemetryLen(servo_count, true);
  if (!has_foot && len != telemetryLen(servo_count, false)) return DecodeError::kBadLength;
  if (size < len) return DecodeError::kTooShort;
  if (size > len) return DecodeError::kBadLength;
  if (data[len - 2] != kTelemetryTail0 || data[len - 1] != kTelemetryTail1) {
    return DecodeError::kBadTail;
  }
  if (telemetrySum(data, len) != data[len - kTelemetryTrailer]) return DecodeError::kBadChecksum;

  Telemetry telemetry;
  telemetry.servo_count = servo_count;
  for (std::size_t i = 0; i < servo_count; ++i) {
    const uint8_t* servo = &data[kTelemetryServoOffset + kBytesPerServo * i];
    telemetry.servos[i].position = readBE16(&servo[0]);
    telemetry.servos[i].speed = readBE16Signed(&servo[2]);
  }
  const uint8_t* imu = &data[imuOffset(servo_count)];
  for (std::size_t k = 0; k < kImuValueCount; ++k) telemetry.imu[k] = readBE16Signed(&imu[2 * k]);
  telemetry.has_foot = has_foot;
  if (has_foot) {
    // The only little-endian block of the frame (vendor layout).
    const uint8_t* foot = &data[footOffset(servo_count)];
    for (std::size_t j = 0; j < kFootSensorCount; ++j) telemetry.foot[j] = readLE16(&foot[2 * j]);
  }
  return telemetry;
}

std::vector<uint8_t> encodeTelemetry(const Telemetry& telemetry) {
  const std::size_t servo_count = telemetry.servo_count;
  if (servo_count > kMaxTelemetryServos) return {};
  const std::size_t len = telemetryLen(servo_count, telemetry.has_foot);
  if (len > kMaxTelemetryLen) return {};

  std::vector<uint8_t> frame(len);
  frame[0] = kTelemetryHeader0;
  frame[1] = kTelemetryHeader1;
  frame[kTelemetryLenOffset] = static_cast<uint8_t>(len);
  for (std::size_t i = 0; i < servo_count; ++i) {
    uint8_t* servo = &frame[kTelemetryServoOffset + kBytesPerServo * i];
    writeBE16(&servo[0], telemetry.servos[i].position);
    writeBE16(&servo[2], static_cast<uint16_t>(telemetry.servos[i].speed));
  }
  uint8_t* imu = &frame[imuOffset(servo_count)];
  for (std::size_t k = 0; k < kImuValueCount; ++k) {
    writeBE16(&imu[2 * k], static_cast<uint16_t>(telemetry.imu[k]));
  }
  if (telemetry.has_foot) {
    uint8_t* foot = &frame[footOffset(servo_count)];
    for (std::size_t j = 0; j < kFootSensorCount; ++j) writeLE16(&foot[2 * j], telemetry.foot[j]);
  }
  frame[len - kTelemetryTrailer] = telemetrySum(frame.data(), len);
  frame[len - 2] = kTelemetryTail0;
  frame[len - 1] = kTelemetryTail1;
  return frame;
}

static_assert(kSyncWritePrefix + syncWriteLen(kMaxSyncWriteServos) <= StreamFramer::kLongestFrame,
              "sync write too long for the framer");

constexpr FrameFamily kSyncWriteFrames{
    "sync_write", kSyncWriteHeader[0],
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeSyncWrite(data, available);
    },
    0};

// Rank 0: asked before servo requests, which share the first byte 0x12.
constexpr FrameFamily kTelemetryFrames{"telemetry", kTelemetryHeader0, probeTelemetry, 0};

}  // namespace serial_robot_driver::protocol::body
