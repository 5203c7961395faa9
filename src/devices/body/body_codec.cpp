#include "serial_robot_driver/devices/body/body_codec.h"

#include <algorithm>
#include <boost/crc.hpp>

#include "serial_robot_driver/protocol/byte_order.h"
#include "serial_robot_driver/protocol/stream_framer.h"

namespace serial_robot_driver::devices::body {

namespace {

// Sync write envelope: header (4), id, LEN (2), the command fields, the servo records, CRC (2).
constexpr std::size_t kIdOffset = 4;
constexpr std::size_t kLenOffset = 5;
constexpr std::size_t kCommandOffset = kSyncWritePrefix;
constexpr auto kCommandFields = protocol::wire::listOf(kSyncWriteCommandFields);
constexpr auto kTargetFields = protocol::wire::listOf(kServoTargetFields);
constexpr std::size_t kFirstTargetOffset = kCommandOffset + kCommandFields.size();
constexpr std::size_t kMinSyncWriteLen = syncWriteLen(0);

// Telemetry envelope: header (2), LEN, the blocks, SUM, tail (2).
constexpr std::size_t kTelemetryLenOffset = 2;
constexpr auto kSampleFields = protocol::wire::listOf(kServoSampleFields);
constexpr std::size_t kMaxTelemetryLen = 255;  // LEN is one byte

std::size_t imuOffset(std::size_t servo_count) {
  return kTelemetryPrefix + kSampleFields.size() * servo_count;
}
std::size_t footOffset(std::size_t servo_count) { return imuOffset(servo_count) + kImuBlockSize; }

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
  protocol::writeLE16(&frame[kLenOffset], static_cast<uint16_t>(syncWriteLen(targets.size())));
  protocol::wire::encodeFields(kCommandFields, SyncWriteCommand{}, &frame[kCommandOffset]);
  std::size_t pos = kFirstTargetOffset;
  for (const ServoTarget& target : targets) {
    protocol::wire::encodeFields(kTargetFields, target, &frame[pos]);
    pos += kTargetFields.size();
  }
  protocol::writeLE16(&frame[pos], dynamixelCrc(frame.data(), pos));
  return frame;
}

protocol::Probe probeSyncWrite(const uint8_t* data, std::size_t available) {
  // FF FF FD 00 then the broadcast id FE: compare as much of this prefix as has arrived.
  const std::size_t header_size = kSyncWriteHeader.size();
  const std::size_t known = std::min(available, header_size + 1);
  for (std::size_t i = 0; i < known; ++i) {
    const uint8_t expected = i < header_size ? kSyncWriteHeader[i] : kBroadcastId;
    if (data[i] != expected) return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  }
  if (available < kSyncWritePrefix) return protocol::Probe::needMore();
  const std::size_t len = protocol::readLE16(data + kLenOffset);
  if (len < kMinSyncWriteLen || (len - kMinSyncWriteLen) % kTargetFields.size() != 0 ||
      (len - kMinSyncWriteLen) / kTargetFields.size() > kMaxSyncWriteServos) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadLength);
  }
  if (available <= kCommandOffset) return protocol::Probe::needMore();
  // Another Dynamixel instruction is not a frame of ours; not counted as an error.
  if (data[kCommandOffset] != kSyncWriteInstruction) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  }
  const std::size_t size = kSyncWritePrefix + len;
  if (available < size) return protocol::Probe::needMore();
  if (dynamixelCrc(data, size - kCrcSize) != protocol::readLE16(data + size - kCrcSize)) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadChecksum);
  }
  return protocol::Probe::frame(size);
}

protocol::Decoded<std::vector<ServoTarget>> decodeSyncWrite(const uint8_t* data, std::size_t size) {
  if (size < kSyncWritePrefix) return protocol::DecodeError::kTooShort;
  if (!std::equal(kSyncWriteHeader.begin(), kSyncWriteHeader.end(), data)) {
    return protocol::DecodeError::kBadHeader;
  }
  const std::size_t len = protocol::readLE16(&data[kLenOffset]);
  if (len < kMinSyncWriteLen || (len - kMinSyncWriteLen) % kTargetFields.size() != 0) {
    return protocol::DecodeError::kBadLength;
  }
  const std::size_t servo_count = (len - kMinSyncWriteLen) / kTargetFields.size();
  if (servo_count > kMaxSyncWriteServos) return protocol::DecodeError::kBadLength;
  if (size < kSyncWritePrefix + len) return protocol::DecodeError::kTooShort;
  if (size > kSyncWritePrefix + len) return protocol::DecodeError::kBadLength;
  if (dynamixelCrc(data, size - kCrcSize) != protocol::readLE16(&data[size - kCrcSize])) {
    return protocol::DecodeError::kBadChecksum;
  }
  // A valid Dynamixel frame, but not the goal-position sync write we speak.
  SyncWriteCommand command;
  protocol::wire::decodeFieldsStatic<kSyncWriteCommandFields>(&data[kCommandOffset], &command);
  const SyncWriteCommand ours;
  if (data[kIdOffset] != kBroadcastId || command.instruction != ours.instruction ||
      command.address != ours.address || command.data_size != ours.data_size) {
    return protocol::DecodeError::kUnexpectedContent;
  }

  std::vector<ServoTarget> targets(servo_count);
  for (std::size_t i = 0; i < servo_count; ++i) {
    protocol::wire::decodeFieldsStatic<kServoTargetFields>(
        &data[kFirstTargetOffset + kTargetFields.size() * i], &targets[i]);
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

protocol::Probe probeTelemetry(const uint8_t* data, std::size_t available,
                               std::size_t servo_count) {
  if (available < 1) return protocol::Probe::needMore();
  if (data[0] != kTelemetryHeader0)
    return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  if (available < 2) return protocol::Probe::needMore();
  if (data[1] != kTelemetryHeader1)
    return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  if (available <= kTelemetryLenOffset) return protocol::Probe::needMore();
  const std::size_t len = data[kTelemetryLenOffset];
  if (len != telemetryLen(servo_count, false) && len != telemetryLen(servo_count, true)) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadLength);
  }
  if (available < len) return protocol::Probe::needMore();
  // Tail first: a wrong tail means the frame boundary itself is wrong.
  if (data[len - 2] != kTelemetryTail0 || data[len - 1] != kTelemetryTail1) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadTail);
  }
  if (telemetrySum(data, len) != data[len - kTelemetryTrailer]) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadChecksum);
  }
  return protocol::Probe::frame(len);
}

protocol::Decoded<Telemetry> decodeTelemetry(const uint8_t* data, std::size_t size,
                                             std::size_t servo_count) {
  if (servo_count > kMaxTelemetryServos) return protocol::DecodeError::kBadLength;
  if (size < kTelemetryLenOffset + 1) return protocol::DecodeError::kTooShort;
  if (data[0] != kTelemetryHeader0 || data[1] != kTelemetryHeader1)
    return protocol::DecodeError::kBadHeader;

  // N is configuration: LEN alone cannot tell 4 more servos from the 16-byte foot block.
  const std::size_t len = data[kTelemetryLenOffset];
  const bool has_foot = len == telemetryLen(servo_count, true);
  if (!has_foot && len != telemetryLen(servo_count, false))
    return protocol::DecodeError::kBadLength;
  if (size < len) return protocol::DecodeError::kTooShort;
  if (size > len) return protocol::DecodeError::kBadLength;
  if (data[len - 2] != kTelemetryTail0 || data[len - 1] != kTelemetryTail1) {
    return protocol::DecodeError::kBadTail;
  }
  if (telemetrySum(data, len) != data[len - kTelemetryTrailer])
    return protocol::DecodeError::kBadChecksum;

  Telemetry telemetry;
  telemetry.servo_count = servo_count;
  for (std::size_t i = 0; i < servo_count; ++i) {
    protocol::wire::decodeFieldsStatic<kServoSampleFields>(
        &data[kTelemetryPrefix + kSampleFields.size() * i], &telemetry.servos[i]);
  }
  // The value fields' types as constants, so each read compiles to a load and a byte swap.
  constexpr protocol::wire::WireType kImuType = kImuValueField.type;
  constexpr protocol::wire::ByteOrder kImuOrder = kImuValueField.order;
  const uint8_t* imu = &data[imuOffset(servo_count)];
  for (std::size_t k = 0; k < kImuValueCount; ++k) {
    telemetry.imu[k] = static_cast<int16_t>(
        protocol::wire::readInteger(imu + kImuType.width * k, kImuType, kImuOrder));
  }
  telemetry.has_foot = has_foot;
  if (has_foot) {
    constexpr protocol::wire::WireType kFootType = kFootValueField.type;
    constexpr protocol::wire::ByteOrder kFootOrder = kFootValueField.order;
    const uint8_t* foot = &data[footOffset(servo_count)];
    for (std::size_t j = 0; j < kFootSensorCount; ++j) {
      telemetry.foot[j] = static_cast<uint16_t>(
          protocol::wire::readInteger(foot + kFootType.width * j, kFootType, kFootOrder));
    }
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
    protocol::wire::encodeFields(kSampleFields, telemetry.servos[i],
                                 &frame[kTelemetryPrefix + kSampleFields.size() * i]);
  }
  const auto write = [&](const protocol::wire::Field<TelemetryValue>& field, std::size_t offset,
                         int64_t value) {
    protocol::wire::writeInteger(&frame[offset], value, field.type, field.order);
  };
  for (std::size_t k = 0; k < kImuValueCount; ++k) {
    const std::size_t offset = imuOffset(servo_count) + kImuValueField.type.width * k;
    write(kImuValueField, offset, telemetry.imu[k]);
  }
  if (telemetry.has_foot) {
    for (std::size_t j = 0; j < kFootSensorCount; ++j) {
      const std::size_t offset = footOffset(servo_count) + kFootValueField.type.width * j;
      write(kFootValueField, offset, telemetry.foot[j]);
    }
  }
  frame[len - kTelemetryTrailer] = telemetrySum(frame.data(), len);
  frame[len - 2] = kTelemetryTail0;
  frame[len - 1] = kTelemetryTail1;
  return frame;
}

static_assert(kSyncWritePrefix + syncWriteLen(kMaxSyncWriteServos) <=
                  protocol::StreamFramer::kLongestFrame,
              "sync write too long for the framer");

constexpr protocol::FrameFamily kSyncWriteFrames{
    "sync_write", kSyncWriteHeader[0],
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeSyncWrite(data, available);
    },
    0,
    // A well-framed sync write may still carry content the decoder refuses (a Dynamixel sync
    // write to another address), never a framing error.
    [](const uint8_t* frame, std::size_t size, std::size_t) {
      const auto decoded = decodeSyncWrite(frame, size);
      return decoded.ok() || decoded.error() == protocol::DecodeError::kUnexpectedContent;
    }};

// Rank 0: asked before servo requests, which share the first byte 0x12.
constexpr protocol::FrameFamily kTelemetryFrames{
    "telemetry", kTelemetryHeader0, probeTelemetry, 0,
    [](const uint8_t* frame, std::size_t size, std::size_t servo_count) {
      const auto decoded = decodeTelemetry(frame, size, servo_count);
      return decoded.ok() && decoded->servo_count == servo_count;
    }};

}  // namespace serial_robot_driver::devices::body
