#include "serial_robot_driver/protocol/servo_bus_codec.h"

#include <algorithm>
#include "serial_robot_driver/protocol/stream_framer.h"

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

std::vector<uint8_t> encodeDamping(uint8_t id, uint16_t power_mw) {
  std::array<uint8_t, 3> content = {id};
  writeLE16(&content[1], power_mw);
  return buildRequest(Command::kDamping, content.data(), content.size());
}

std::vector<uint8_t> encodeReadAngle(uint8_t id) {
  return buildIdOnlyRequest(Command::kReadAngle, id);
}

namespace {

// The layout of each move after the id: angle (i16 / i32), interval or velocity (u16 / u32),
// the ramps (accel, decel u16) or not, then power (u16). One description for encode and decode.
struct MoveLayout {
  std::size_t angle_size;
  std::size_t second_size;
  bool by_velocity;
  bool ramps;
};

MoveLayout moveLayout(Command cmd) {
  switch (cmd) {
    case Command::kMoveByInterval:
      return {2, 2, false, true};
    case Command::kMoveByVelocity:
      return {2, 2, true, true};
    case Command::kMultiTurnMove:
      return {4, 4, false, false};
    case Command::kMultiTurnMoveByInterval:
      return {4, 4, false, true};
    case Command::kMultiTurnMoveByVelocity:
      return {4, 2, true, true};
    default:  // ROTATE
      return {2, 2, false, false};
  }
}

void writeField(uint8_t* at, std::size_t size, uint32_t value) {
  if (size == 2) {
    writeLE16(at, static_cast<uint16_t>(value));
  } else {
    writeLE32(at, value);
  }
}

std::vector<uint8_t> buildMove(const MoveCommand& move) {
  const MoveLayout layout = moveLayout(move.cmd);
  std::array<uint8_t, 1 + 4 + 4 + 3 * 2> content{};
  std::size_t size = 0;
  content[size++] = move.id;
  const auto angle = static_cast<uint32_t>(move.angle_decidegrees);
  writeField(&content[size], layout.angle_size,
             layout.angle_size == 2 ? static_cast<uint16_t>(static_cast<int16_t>(angle)) : angle);
  size += layout.angle_size;
  writeField(&content[size], layout.second_size,
             layout.by_velocity ? move.velocity_decidegrees_per_s : move.interval_ms);
  size += layout.second_size;
  if (layout.ramps) {
    writeLE16(&content[size], move.ramps.accel_ms);
    writeLE16(&content[size + 2], move.ramps.decel_ms);
    size += 4;
  }
  writeLE16(&content[size], move.ramps.power_mw);
  size += 2;
  return buildRequest(move.cmd, content.data(), size);
}

MoveCommand moveOf(Command cmd, uint8_t id, int32_t angle, uint32_t interval_ms, uint16_t velocity,
                   const MoveRamps& ramps) {
  MoveCommand move;
  move.cmd = cmd;
  move.id = id;
  move.angle_decidegrees = angle;
  move.interval_ms = interval_ms;
  move.velocity_decidegrees_per_s = velocity;
  move.ramps = ramps;
  return move;
}

}  // namespace

std::vector<uint8_t> encodeMove(const MoveCommand& move) { return buildMove(move); }

std::vector<uint8_t> encodeSpin(const SpinCommand& spin) {
  return encodeSpin(spin.id, spin.clockwise, spin.mode, spin.speed_dps, spin.value);
}

bool isMove(Command cmd) {
  return cmd == Command::kRotate ||
         (cmd >= Command::kMoveByInterval && cmd <= Command::kMultiTurnMoveByVelocity);
}
bool isMultiTurn(Command cmd) { return moveLayout(cmd).angle_size == 4; }
bool isByVelocity(Command cmd) { return moveLayout(cmd).by_velocity; }
bool hasRamps(Command cmd) { return moveLayout(cmd).ramps; }

Decoded<MoveCommand> decodeMove(const Packet& request) {
  const auto cmd = static_cast<Command>(request.cmd);
  if (!isMove(cmd)) return DecodeError::kUnknownCommand;
  const MoveLayout layout = moveLayout(cmd);
  const std::size_t size = 1 + layout.angle_size + layout.second_size + (layout.ramps ? 4 : 0) + 2;
  if (request.content_size != size) return DecodeError::kBadLength;
  const uint8_t* at = request.content.data() + 1;
  MoveCommand move;
  move.cmd = cmd;
  move.id = request.id();
  move.angle_decidegrees =
      layout.angle_size == 2 ? readLE16Signed(at) : static_cast<int32_t>(readLE32(at));
  at += layout.angle_size;
  const uint32_t second = layout.second_size == 2 ? readLE16(at) : readLE32(at);
  if (layout.by_velocity) {
    move.velocity_decidegrees_per_s = static_cast<uint16_t>(second);
  } else {
    move.interval_ms = second;
  }
  at += layout.second_size;
  if (layout.ramps) {
    move.ramps.accel_ms = readLE16(at);
    move.ramps.decel_ms = readLE16(at + 2);
    at += 4;
  }
  move.ramps.power_mw = readLE16(at);
  return move;
}

Decoded<SpinCommand> decodeSpin(const Packet& request) {
  if (request.cmd != static_cast<uint8_t>(Command::kSpin)) return DecodeError::kUnknownCommand;
  if (request.content_size != 6) return DecodeError::kBadLength;
  SpinCommand spin;
  spin.id = request.id();
  const uint8_t method = request.content[1];
  spin.clockwise = (method & kSpinDirectionBit) != 0;
  spin.mode = static_cast<SpinMode>(method & kSpinModeMask);
  spin.speed_dps = readLE16(&request.content[2]);
  spin.value = readLE16(&request.content[4]);
  return spin;
}

std::vector<uint8_t> angleAnswerContent(const AngleAnswer& answer) {
  std::vector<uint8_t> content(3);
  content[0] = answer.id;
  writeLE16(&content[1], static_cast<uint16_t>(answer.angle_decidegrees));
  return content;
}

Decoded<AngleAnswer> decodeAngleAnswer(const Packet& answer) {
  if (answer.content_size != 3) return DecodeError::kBadLength;
  return AngleAnswer{answer.content[0], readLE16Signed(&answer.content[1])};
}

Decoded<MultiTurnAngle> decodeMultiTurnAngle(const Packet& answer) {
  return decodeMultiTurnAngle(answer.content.data(), answer.content_size);
}

std::vector<uint8_t> readDataAnswerContent(uint8_t id, const ParamInfo& param, int64_t value) {
  std::vector<uint8_t> content = {id, param.data_id};
  uint8_t bytes[8] = {};
  const std::size_t size = writeValue(param, value, bytes);
  content.insert(content.end(), bytes, bytes + size);
  return content;
}

Decoded<int64_t> decodeReadDataAnswer(const Packet& answer, const ParamInfo& param) {
  constexpr std::size_t kHeader = 2;  // id, data_id
  if (answer.content_size < kHeader) return DecodeError::kBadLength;
  const std::optional<int64_t> value =
      readValue(param, answer.content.data() + kHeader, answer.content_size - kHeader);
  if (!value) return DecodeError::kBadLength;
  return *value;
}

std::vector<uint8_t> encodeRotate(uint8_t id, int16_t angle_decidegrees, uint16_t interval_ms,
                                  uint16_t power_mw) {
  MoveRamps ramps;
  ramps.power_mw = power_mw;
  return buildMove(moveOf(Command::kRotate, id, angle_decidegrees, interval_ms, 0, ramps));
}

std::vector<uint8_t> encodeMoveByInterval(uint8_t id, int16_t angle_decidegrees,
                                          uint16_t interval_ms, const MoveRamps& ramps) {
  return buildMove(moveOf(Command::kMoveByInterval, id, angle_decidegrees, interval_ms, 0, ramps));
}

std::vector<uint8_t> encodeMoveByVelocity(uint8_t id, int16_t angle_decidegrees,
                                          uint16_t velocity_decidegrees_per_s,
                                          const MoveRamps& ramps) {
  return buildMove(moveOf(Command::kMoveByVelocity, id, angle_decidegrees, 0,
                          velocity_decidegrees_per_s, ramps));
}

std::vector<uint8_t> encodeMultiTurnMove(uint8_t id, int32_t angle_decidegrees,
                                         uint32_t interval_ms, uint16_t power_mw) {
  MoveRamps ramps;
  ramps.power_mw = power_mw;
  return buildMove(moveOf(Command::kMultiTurnMove, id, angle_decidegrees, interval_ms, 0, ramps));
}

std::vector<uint8_t> encodeMultiTurnMoveByInterval(uint8_t id, int32_t angle_decidegrees,
                                                   uint32_t interval_ms, const MoveRamps& ramps) {
  return buildMove(
      moveOf(Command::kMultiTurnMoveByInterval, id, angle_decidegrees, interval_ms, 0, ramps));
}

std::vector<uint8_t> encodeMultiTurnMoveByVelocity(uint8_t id, int32_t angle_decidegrees,
                                                   uint16_t velocity_decidegrees_per_s,
                                                   const MoveRamps& ramps) {
  return buildMove(moveOf(Command::kMultiTurnMoveByVelocity, id, angle_decidegrees, 0,
                          velocity_decidegrees_per_s, ramps));
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

static_assert(kMaxFrameSize <= StreamFramer::kLongestFrame, "servo frame too long for the framer");

constexpr FrameFamily kResponseFrames{
    "servo_response", kResponseHeader0,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeResponse(data, available);
    },
    0};

// Rank 1: after the body's telemetry, which shares the first byte 0x12.
constexpr FrameFamily kRequestFrames{
    "servo_request", kRequestHeader0,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeRequest(data, available);
    },
    1};

}  // namespace serial_robot_driver::protocol::servo
