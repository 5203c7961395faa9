#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"

#include <algorithm>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "servo_layouts.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

constexpr std::size_t kCmdOffset = 2;
constexpr std::size_t kSizeOffset = 3;
constexpr std::size_t kContentOffset = 4;

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

// The request `fields` lay out for `record`, followed by `tail_size` bytes of `tail`.
template <typename Record>
std::vector<uint8_t> buildRequest(Command cmd, layout::FieldList<Record> fields,
                                  const Record& record, const uint8_t* tail = nullptr,
                                  std::size_t tail_size = 0) {
  std::array<uint8_t, kMaxContent> content{};
  const std::size_t size = fields.size();
  protocol::wire::encodeFields(fields, record, content.data());
  std::copy(tail, tail + tail_size, content.begin() + size);
  return buildRequest(cmd, content.data(), size + tail_size);
}

std::vector<uint8_t> buildIdOnlyRequest(Command cmd, uint8_t id) {
  return buildRequest(cmd, layout::listOf(layout::kId), layout::IdContent{id});
}

// A CONTENT (answer, simulator side) as `fields` lay it out, followed by `tail_size` bytes.
template <typename Record>
std::vector<uint8_t> contentOf(layout::FieldList<Record> fields, const Record& record,
                               const uint8_t* tail = nullptr, std::size_t tail_size = 0) {
  std::vector<uint8_t> content(fields.size() + tail_size);
  protocol::wire::encodeFields(fields, record, content.data());
  std::copy(tail, tail + tail_size, content.begin() + fields.size());
  return content;
}

// `record` with the members `fields` describe read from `content`, which must be exactly their
// size.
template <typename Record>
protocol::Decoded<Record> decodeExactly(layout::FieldList<Record> fields, const uint8_t* content,
                                        std::size_t content_size, Record record = {}) {
  if (content_size != fields.size()) return protocol::DecodeError::kBadLength;
  protocol::wire::decodeFields(fields, content, &record);
  return record;
}

protocol::Decoded<Packet> decodePacket(uint8_t header0, uint8_t header1, const uint8_t* data,
                                       std::size_t size) {
  if (size < kContentOffset) return protocol::DecodeError::kTooShort;
  if (data[0] != header0 || data[1] != header1) return protocol::DecodeError::kBadHeader;
  const uint8_t content_size = data[kSizeOffset];
  if (content_size > kMaxContent) return protocol::DecodeError::kBadLength;
  if (size < content_size + kOverhead) return protocol::DecodeError::kTooShort;
  if (size > content_size + kOverhead) return protocol::DecodeError::kBadLength;
  const uint8_t cmd = data[kCmdOffset];
  if (!isKnownCommand(cmd)) return protocol::DecodeError::kUnknownCommand;
  if (byteSum(data, size - 1) != data[size - 1]) return protocol::DecodeError::kBadChecksum;

  Packet packet;
  packet.cmd = cmd;
  packet.content_size = content_size;
  std::copy(data + kContentOffset, data + kContentOffset + content_size, packet.content.begin());
  return packet;
}

protocol::Probe probePacket(uint8_t header0, uint8_t header1, const uint8_t* data,
                            std::size_t available);

}  // namespace

uint8_t byteSum(const uint8_t* data, std::size_t size) {
  uint8_t sum = 0;
  for (std::size_t i = 0; i < size; ++i) sum = static_cast<uint8_t>(sum + data[i]);
  return sum;
}

uint8_t spinMethod(bool clockwise, SpinMode mode) {
  return static_cast<uint8_t>((clockwise ? layout::kSpinDirectionBit : 0) |
                              (static_cast<uint8_t>(mode) & layout::kSpinModeMask));
}

std::vector<uint8_t> encodePing(uint8_t id) { return buildIdOnlyRequest(Command::kPing, id); }

std::vector<uint8_t> encodeResetUserData(uint8_t id) {
  return buildIdOnlyRequest(Command::kResetUserData, id);
}

std::vector<uint8_t> encodeReadData(uint8_t id, uint8_t data_id) {
  return buildRequest(Command::kReadData, layout::listOf(layout::kDataId),
                      layout::DataIdContent{id, data_id});
}

std::vector<uint8_t> encodeWriteData(uint8_t id, const ParamInfo& param, int64_t value) {
  std::array<uint8_t, largestTypeSize()> value_bytes{};
  const std::size_t value_size = writeValue(param, value, value_bytes.data());
  return buildRequest(Command::kWriteData, layout::listOf(layout::kDataId),
                      layout::DataIdContent{id, param.data_id}, value_bytes.data(), value_size);
}

std::vector<uint8_t> encodeReadBatchData(uint8_t id) {
  return buildIdOnlyRequest(Command::kReadBatchData, id);
}

std::vector<uint8_t> encodeWriteBatchData(uint8_t id,
                                          const std::array<uint8_t, kUserBlockSize>& block) {
  return buildRequest(Command::kWriteBatchData, layout::listOf(layout::kId), layout::IdContent{id},
                      block.data(), block.size());
}

std::vector<uint8_t> encodeSpin(uint8_t id, bool clockwise, SpinMode mode, uint16_t speed_dps,
                                uint16_t value) {
  return encodeSpin(SpinCommand{id, clockwise, mode, speed_dps, value});
}

std::vector<uint8_t> encodeDamping(uint8_t id, uint16_t power_mw) {
  return buildRequest(Command::kDamping, layout::listOf(layout::kDamping),
                      layout::PowerContent{id, power_mw});
}

protocol::Decoded<uint16_t> decodeDamping(const Packet& request) {
  if (request.cmd != static_cast<uint8_t>(Command::kDamping))
    return protocol::DecodeError::kUnknownCommand;
  const auto damping =
      decodeExactly(layout::listOf(layout::kDamping), request.content.data(), request.content_size);
  if (!damping) return damping.error();
  return damping->power_mw;
}

std::vector<uint8_t> encodeReadAngle(uint8_t id) {
  return buildIdOnlyRequest(Command::kReadAngle, id);
}

namespace {

std::vector<uint8_t> buildMove(const MoveCommand& move) {
  return buildRequest(move.cmd, layout::moveFields(move.cmd), move);
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
  return buildRequest(Command::kSpin, layout::listOf(layout::kSpin), spin);
}

bool isMove(Command cmd) { return layout::moveFields(cmd).count > 0; }
bool isMultiTurn(Command cmd) {
  const auto* angle = layout::moveFields(cmd).find("angle");
  return angle != nullptr && angle->type.width == protocol::wire::kI32.width;
}
bool isByVelocity(Command cmd) { return layout::moveFields(cmd).has("velocity"); }
bool hasRamps(Command cmd) { return layout::moveFields(cmd).has("accel"); }

protocol::Decoded<MoveCommand> decodeMove(const Packet& request) {
  const auto cmd = static_cast<Command>(request.cmd);
  if (!isMove(cmd)) return protocol::DecodeError::kUnknownCommand;
  MoveCommand move;
  move.cmd = cmd;
  return decodeExactly(layout::moveFields(cmd), request.content.data(), request.content_size, move);
}

protocol::Decoded<SpinCommand> decodeSpin(const Packet& request) {
  if (request.cmd != static_cast<uint8_t>(Command::kSpin))
    return protocol::DecodeError::kUnknownCommand;
  return decodeExactly(layout::listOf(layout::kSpin), request.content.data(), request.content_size);
}

std::vector<uint8_t> pingAnswerContent(uint8_t id) {
  return contentOf(layout::listOf(layout::kId), layout::IdContent{id});
}

std::vector<uint8_t> resultAnswerContent(uint8_t id, bool ok) {
  return contentOf(layout::listOf(layout::kIdResult),
                   layout::ResultContent{id, static_cast<uint8_t>(ok ? 1 : 0)});
}

std::vector<uint8_t> writeDataAnswerContent(uint8_t id, uint8_t data_id, bool ok) {
  return contentOf(layout::listOf(layout::kDataIdResult),
                   layout::DataIdResult{id, data_id, static_cast<uint8_t>(ok ? 1 : 0)});
}

std::vector<uint8_t> angleAnswerContent(const AngleAnswer& answer) {
  return contentOf(layout::listOf(layout::kAngleAnswer), answer);
}

protocol::Decoded<AngleAnswer> decodeAngleAnswer(const Packet& answer) {
  return decodeExactly(layout::listOf(layout::kAngleAnswer), answer.content.data(),
                       answer.content_size);
}

protocol::Decoded<MultiTurnAngle> decodeMultiTurnAngle(const Packet& answer) {
  return decodeMultiTurnAngle(answer.content.data(), answer.content_size);
}

std::vector<uint8_t> readDataAnswerContent(uint8_t id, const ParamInfo& param, int64_t value) {
  std::array<uint8_t, largestTypeSize()> value_bytes{};
  const std::size_t value_size = writeValue(param, value, value_bytes.data());
  return contentOf(layout::listOf(layout::kDataId), layout::DataIdContent{id, param.data_id},
                   value_bytes.data(), value_size);
}

protocol::Decoded<int64_t> decodeReadDataAnswer(const Packet& answer, const ParamInfo& param) {
  const std::size_t value_offset = layout::listOf(layout::kDataId).size();
  if (answer.content_size < value_offset) return protocol::DecodeError::kBadLength;
  const std::optional<int64_t> value =
      readValue(param, answer.content.data() + value_offset, answer.content_size - value_offset);
  if (!value) return protocol::DecodeError::kBadLength;
  return *value;
}

protocol::Decoded<DataContent> decodeDataContent(const Packet& packet) {
  const auto fields = layout::listOf(layout::kDataId);
  if (packet.content_size < fields.size()) return protocol::DecodeError::kBadLength;
  layout::DataIdContent head;
  protocol::wire::decodeFields(fields, packet.content.data(), &head);
  DataContent data;
  data.id = head.id;
  data.data_id = head.data_id;
  data.value_size = packet.content_size - fields.size();
  if (data.value_size > data.value.size()) return protocol::DecodeError::kBadLength;
  std::copy_n(packet.content.begin() + fields.size(), data.value_size, data.value.begin());
  return data;
}

std::vector<uint8_t> userBlockAnswerContent(uint8_t id,
                                            const std::array<uint8_t, kUserBlockSize>& block) {
  return contentOf(layout::listOf(layout::kId), layout::IdContent{id}, block.data(), block.size());
}

protocol::Decoded<std::array<uint8_t, kUserBlockSize>> decodeUserBlock(const Packet& packet) {
  const std::size_t block_offset = layout::listOf(layout::kId).size();
  if (packet.content_size != block_offset + kUserBlockSize)
    return protocol::DecodeError::kBadLength;
  std::array<uint8_t, kUserBlockSize> block{};
  std::copy_n(packet.content.begin() + block_offset, kUserBlockSize, block.begin());
  return block;
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

protocol::Decoded<MultiTurnAngle> decodeMultiTurnAngle(const uint8_t* content, std::size_t size) {
  return decodeExactly(layout::listOf(layout::kMultiTurnAngle), content, size);
}

std::vector<uint8_t> multiTurnAngleContent(const MultiTurnAngle& angle) {
  return contentOf(layout::listOf(layout::kMultiTurnAngle), angle);
}

namespace {
protocol::Probe probePacket(uint8_t header0, uint8_t header1, const uint8_t* data,
                            std::size_t available) {
  if (available < 1) return protocol::Probe::needMore();
  if (data[0] != header0) return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  if (available < 2) return protocol::Probe::needMore();
  if (data[1] != header1) return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  if (available <= kSizeOffset) return protocol::Probe::needMore();
  const uint8_t cmd = data[kCmdOffset];
  const uint8_t content_size = data[kSizeOffset];
  // Both mean a corrupted or misaligned header, but they are counted apart: an unknown CMD may
  // also be a newer firmware's command.
  if (!isKnownCommand(cmd)) return protocol::Probe::invalid(protocol::DecodeError::kUnknownCommand);
  if (content_size > kMaxContent)
    return protocol::Probe::invalid(protocol::DecodeError::kBadLength);
  const std::size_t size = content_size + kOverhead;
  if (available < size) return protocol::Probe::needMore();
  if (byteSum(data, size - 1) != data[size - 1])
    return protocol::Probe::invalid(protocol::DecodeError::kBadChecksum);
  return protocol::Probe::frame(size);
}
}  // namespace

protocol::Probe probeResponse(const uint8_t* data, std::size_t available) {
  return probePacket(kResponseHeader0, kResponseHeader1, data, available);
}

protocol::Probe probeRequest(const uint8_t* data, std::size_t available) {
  return probePacket(kRequestHeader0, kRequestHeader1, data, available);
}

protocol::Decoded<Packet> decodeResponse(const uint8_t* data, std::size_t size) {
  return decodePacket(kResponseHeader0, kResponseHeader1, data, size);
}

protocol::Decoded<Packet> decodeRequest(const uint8_t* data, std::size_t size) {
  return decodePacket(kRequestHeader0, kRequestHeader1, data, size);
}

std::vector<uint8_t> encodeResponse(Command cmd, const std::vector<uint8_t>& content) {
  // No servo answers with more than kMaxContent bytes; refuse rather than truncate N.
  if (content.size() > kMaxContent) return {};
  return buildPacket(kResponseHeader0, kResponseHeader1, cmd, content.data(), content.size());
}

static_assert(kMaxFrameSize <= protocol::StreamFramer::kLongestFrame,
              "servo frame too long for the framer");

constexpr protocol::FrameFamily kResponseFrames{
    "servo_response", kResponseHeader0,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeResponse(data, available);
    },
    0,
    [](const uint8_t* frame, std::size_t size, std::size_t) {
      const auto decoded = decodeResponse(frame, size);
      return decoded.ok() && decoded->content_size + kOverhead == size;
    }};

// Rank 1: after the body's telemetry, which shares the first byte 0x12.
constexpr protocol::FrameFamily kRequestFrames{
    "servo_request", kRequestHeader0,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeRequest(data, available);
    },
    1,
    [](const uint8_t* frame, std::size_t size, std::size_t) {
      const auto decoded = decodeRequest(frame, size);
      return decoded.ok() && decoded->content_size + kOverhead == size;
    }};

}  // namespace serial_robot_driver::devices::servo_bus
