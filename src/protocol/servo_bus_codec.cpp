#include "serial_robot_driver/protocol/servo_bus_codec.h"

#include <algorithm>

#include "serial_robot_driver/protocol/byte_order.h"

namespace serial_robot_driver::protocol::servo {

namespace {

constexpr std::size_t kCmdOffset = 2;
constexpr std::size_t kSizeOffset = 3;
constexpr std::size_t kContentOffset = 4;
constexpr uint8_t kSpinDirectionBit = 0x80;
constexpr uint8_t kSpinModeMask = 0x03;

// Builds HEADER | CMD | N | CONTENT | SUM. Callers keep N <= kMaxContent.
std::vector<uint8_t> buildPacket(uint8_t header0, uint8_t header1, Command cmd,
                                 const uint8_t* content, std::size_t content_size) {
  std::vector<uint8_t> packet;
  packet.reserve(content_size + kOverhead);
  packet.push_back(header0);
  packet.push_back(header1);
  packet.push_back(static_cast<uint8_t>(cmd));
  packet.push_back(static_cast<uint8_t>(content_size));
  packet.insert(packet.end(), content, content + content_size);
  packet.push_back(byteSum(packet.data(), packet.size()));
  return packet;
}

std::vector<uint8_t> buildRequest(Command cmd, const uint8_t* content, std::size_t content_size) {
  return buildPacket(kRequestHeader0, kRequestHeader1, cmd, content, content_size);
}

std::vector<uint8_t> buildIdOnlyRequest(Command cmd, uint8_t id) {
  return buildRequest(cmd, &id, 1);
}

Decoded<Packet> decodePacket(uint8_t header0, uint8_t header1, const uint8_t* data,
                             std::size_t size) {
  if (size < kContentOffset) return DecodeError::kTooShort;
  if (data[0] != header0 || data[1] != header1) return DecodeError::kBadHeader;
  const uint8_t content_size = data[kSizeOffset];
  if (content_size > kMaxContent) return DecodeError::kBadLength;
  if (size < content_size + kOverhead) return DecodeError::kTooShort;
  if (size > content_size + kOverhead) return DecodeError::kBadLength;
  const uint8_t cmd = data[kCmdOffset];
  if (!isKnownCommand(cmd)) return DecodeError::kUnknownCommand;
  if (byteSum(data, size - 1) != data[size - 1]) return DecodeError::kBadChecksum;

  Packet packet;
  packet.cmd = cmd;
  packet.content_size = content_size;
  std::copy(data + kContentOffset, data + kContentOffset + content_size, packet.content.begin());
  return packet;
}

Probe probePacket(uint8_t header0, uint8_t header1, const uint8_t* data, std::size_t available);

}  // namespace

uint8_t byteSum(const uint8_t* data, std::size_t size) {
  uint8_t sum = 0;
  for (std::size_t i = 0; i < size; ++i) sum = static_cast<uint8_t>(sum + data[i]);
  return sum;
}

uint8_t spinMethod(bool clockwise, SpinMode mode) {
  return static_cast<uint8_t>((clockwise ? kSpinDirectionBit : 0) |
                              (static_cast<uint8_t>(mode) & kSpinModeMask));
}

std::vector<uint8_t> encodePing(uint8_t id) { return buildIdOnlyRequest(Command::kPing, id); }

std::vector<uint8_t> encodeResetUserData(uint8_t id) {
  return buildIdOnlyRequest(Command::kResetUserData, id);
}

std::vector<uint8_t> encodeReadData(uint8_t id, uint8_t data_id) {
  const std::array<uint8_t, 2> content = {id, data_id};
  return buildRequest(Command::kReadData, content.data(), content.size());
}

std::vector<uint8_t> encodeWriteData(uint8_t id, const ParamInfo& param, int64_t value) {
  std::array<uint8_t, 2 + 4> content = {id, param.data_id};  // room for the widest type (u32)
  const std::size_t value_size = writeValue(param, value, &content[2]);
  return buildRequest(Command::kWriteData, content.data(), 2 + value_size);
}

std::vector<uint8_t> encodeReadBatchData(uint8_t id) {
  return buildIdOnlyRequest(Command::kReadBatchData, id);
}

std::vector<uint8_t> encodeWriteBatchData(uint8_t id,
                                          const std::array<uint8_t, kUserBlockSize>& block) {
  std::array<uint8_t, 1 + kUserBlockSize> content{};
  content[0] = id;
  std::copy(block.begin(), block.end(), content.begin() + 1);
  return buildRequest(Command::kWriteBatchData, content.data(), content.size());
}

std::vector<uint8_t> encodeSpin(uint8_t id, bool clockwise, SpinMode mode, uint16_t speed_dps,
                                uint16_t value) {
  std::array<uint8_t, 6> content = {id, spinMethod(clockwise, mode)};
  writeLE16(&content[2], speed_dps);
  writeLE16(&content[4], value);
  return buildRequest(Command::kSpin, content.data(), content.size());
}

std::vector<uint8_t> encodeRotate(uint8_t id, int16_t angle_decidegrees, uint16_t interval_ms,
                                  uint16_t power_mw) {
  std::array<uint8_t, 7> content = {id};
  writeLE16(&content[1], static_cast<uint16_t>(angle_decidegrees));
  writeLE16(&content[3], interval_ms);
  writeLE16(&content[5], power_mw);
  return buildRequest(Command::kRotate, content.data(), content.size());
}

std::vector<uint8_t> encodeDamping(uint8_t id, uint16_t power_mw) {
  std::array<uint8_t, 3> content = {id};
  writeLE16(&content[1], power_mw);
  return buildRequest(Command::kDamping, content.data(), content.size());
}

std::vector<uint8_t> encodeReadAngle(uint8_t id) {
  return buildIdOnlyRequest(Command::kReadAngle, id);
}

namespace {

constexpr std::size_t kAngle16Size = 2;
constexpr std::size_t kAngle32Size = 4;

// id | angle (i16 or i32) | u16 or u32 | the ramps (accel, decel, power), all little-endian.
std::vector<uint8_t> buildMove(Command cmd, uint8_t id, int32_t angle, std::size_t angle_size,
                               uint32_t interval_or_velocity, std::size_t second_size,
                               const MoveRamps* ramps, uint16_t power_mw) {
  std::array<uint8_t, 1 + 4 + 4 + 3 * 2> content{};
  std::size_t size = 0;
  content[size++] = id;
  if (angle_size == kAngle16Size) {
    writeLE16(&content[size], static_cast<uint16_t>(static_cast<int16_t>(angle)));
  } else {
    writeLE32(&content[size], static_cast<uint32_t>(angle));
  }
  size += angle_size;
  if (second_size == 2) {
    writeLE16(&content[size], static_cast<uint16_t>(interval_or_velocity));
  } else {
    writeLE32(&content[size], interval_or_velocity);
  }
  size += second_size;
  if (ramps != nullptr) {
    writeLE16(&content[size], ramps->accel_ms);
    writeLE16(&content[size + 2], ramps->decel_ms);
    size += 4;
    power_mw = ramps->power_mw;
  }
  writeLE16(&content[size], power_mw);
  size += 2;
  return buildRequest(cmd, content.data(), size);
}

}  // namespace

std::vector<uint8_t> encodeMoveByInterval(uint8_t id, int16_t angle_decidegrees,
                                          uint16_t interval_ms, const MoveRamps& ramps) {
  return buildMove(Command::kMoveByInterval, id, angle_decidegrees, kAngle16Size, interval_ms, 2,
                   &ramps, 0);
}

std::vector<uint8_t> encodeMoveByVelocity(uint8_t id, int16_t angle_decidegrees,
                                          uint16_t velocity_decidegrees_per_s,
                                          const MoveRamps& ramps) {
  return buildMove(Command::kMoveByVelocity, id, angle_decidegrees, kAngle16Size,
                   velocity_decidegrees_per_s, 2, &ramps, 0);
}

std::vector<uint8_t> encodeMultiTurnMove(uint8_t id, int32_t angle_decidegrees,
                                         uint32_t interval_ms, uint16_t power_mw) {
  return buildMove(Command::kMultiTurnMove, id, angle_decidegrees, kAngle32Size, interval_ms, 4,
                   nullptr, power_mw);
}

std::vector<uint8_t> encodeMultiTurnMoveByInterval(uint8_t id, int32_t angle_decidegrees,
                                                   uint32_t interval_ms, const MoveRamps& ramps) {
  return buildMove(Command::kMultiTurnMoveByInterval, id, angle_decidegrees, kAngle32Size,
                   interval_ms, 4, &ramps, 0);
}

std::vector<uint8_t> encodeMultiTurnMoveByVelocity(uint8_t id, int32_t angle_decidegrees,
                                                   uint16_t velocity_decidegrees_per_s,
                                                   const MoveRamps& ramps) {
  return buildMove(Command::kMultiTurnMoveByVelocity, id, angle_decidegrees, kAngle32Size,
                   velocity_decidegrees_per_s, 2, &ramps, 0);
}

std::vector<uint8_t> encodeReadMultiTurnAngle(uint8_t id) {
  return buildIdOnlyRequest(Command::kReadMultiTurnAngle, id);
}

Decoded<MultiTurnAngle> decodeMultiTurnAngle(const uint8_t* content, std::size_t size) {
  if (size != kMultiTurnAngleAnswerSize) return DecodeError::kBadLength;
  MultiTurnAngle angle;
  angle.id = content[0];
  angle.angle_decidegrees = static_cast<int32_t>(readLE32(content + 1));
  angle.turns = readLE16Signed(content + 5);
  return angle;
}

std::vector<uint8_t> multiTurnAngleContent(const MultiTurnAngle& angle) {
  std::vector<uint8_t> content(kMultiTurnAngleAnswerSize);
  content[0] = angle.id;
  writeLE32(&content[1], static_cast<uint32_t>(angle.angle_decidegrees));
  writeLE16(&content[5], static_cast<uint16_t>(angle.turns));
  return content;
}

namespace {
Probe probePacket(uint8_t header0, uint8_t header1, const uint8_t* data, std::size_t available) {
  if (available < 1) return Probe::needMore();
  if (data[0] != header0) return Probe::invalid(DecodeError::kBadHeader);
  if (available < 2) return Probe::needMore();
  if (data[1] != header1) return Probe::invalid(DecodeError::kBadHeader);
  if (available <= kSizeOffset) return Probe::needMore();
  const uint8_t cmd = data[kCmdOffset];
  const uint8_t content_size = data[kSizeOffset];
  // Both mean a corrupted or misaligned header, but they are counted apart: an unknown CMD may
  // also be a newer firmware's command.
  if (!isKnownCommand(cmd)) return Probe::invalid(DecodeError::kUnknownCommand);
  if (content_size > kMaxContent) return Probe::invalid(DecodeError::kBadLength);
  const std::size_t size = content_size + kOverhead;
  if (available < size) return Probe::needMore();
  if (byteSum(data, size - 1) != data[size - 1]) return Probe::invalid(DecodeError::kBadChecksum);
  return Probe::frame(size);
}
}  // namespace

Probe probeResponse(const uint8_t* data, std::size_t available) {
  return probePacket(kResponseHeader0, kResponseHeader1, data, available);
}

Probe probeRequest(const uint8_t* data, std::size_t available) {
  return probePacket(kRequestHeader0, kRequestHeader1, data, available);
}

Decoded<Packet> decodeResponse(const uint8_t* data, std::size_t size) {
  return decodePacket(kResponseHeader0, kResponseHeader1, data, size);
}

Decoded<Packet> decodeRequest(const uint8_t* data, std::size_t size) {
  return decodePacket(kRequestHeader0, kRequestHeader1, data, size);
}

std::vector<uint8_t> encodeResponse(Command cmd, const std::vector<uint8_t>& content) {
  // No servo answers with more than kMaxContent bytes; refuse rather than truncate N.
  if (content.size() > kMaxContent) return {};
  return buildPacket(kResponseHeader0, kResponseHeader1, cmd, content.data(), content.size());
}

}  // namespace serial_robot_driver::protocol::servo
