#include "serial_robot_driver/devices/base/base_codec.h"

#include <algorithm>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/protocol/wire_fields.h"

namespace serial_robot_driver::devices::base {

namespace {

constexpr auto kBE = protocol::wire::ByteOrder::kBig;
constexpr uint8_t kMaxBatteryPercent = 100;

// Frame envelope: header (2), LEN, SEQ, MSGID, PARAM..., XOR.
constexpr std::size_t kLenOffset = 2;
constexpr std::size_t kSeqOffset = 3;
constexpr std::size_t kMsgIdOffset = 4;
constexpr std::size_t kParamsOffset = 5;

// The PARAM of each frame kind, as one field list each.
constexpr std::array<protocol::wire::Field<WheelSpeed>, 3> kWheelSpeedParams = {{
    protocol::wire::field<&WheelSpeed::left_ticks>("left", protocol::wire::kI16, kBE,
                                                   "ticks/period"),
    protocol::wire::field<&WheelSpeed::right_ticks>("right", protocol::wire::kI16, kBE,
                                                    "ticks/period"),
    protocol::wire::reservedField<WheelSpeed>("reserved", 4),
}};
struct BatteryLevel {
  uint8_t percent = 0;
};
constexpr std::array<protocol::wire::Field<BatteryLevel>, 1> kBatteryReplyParams = {
    {protocol::wire::field<&BatteryLevel::percent>("percent", protocol::wire::kU8, kBE, "%")}};
// The vendor's one-byte commands (battery request, Reset, clear encoders, the error status).
struct NoParams {};
constexpr std::array<protocol::wire::Field<NoParams>, 1> kSimpleCommandParams = {
    {protocol::wire::reservedField<NoParams>("reserved", 1)}};

template <typename Record>
std::vector<uint8_t> buildFrame(uint8_t seq, MsgId msg_id, protocol::wire::FieldList<Record> params,
                                const Record& record) {
  const std::size_t len = 1 + params.size();  // MSGID + PARAM
  std::vector<uint8_t> frame(frameSize(static_cast<uint8_t>(len)));
  frame[0] = kHeader0;
  frame[1] = kHeader1;
  frame[kLenOffset] = static_cast<uint8_t>(len);
  frame[kSeqOffset] = seq;
  frame[kMsgIdOffset] = static_cast<uint8_t>(msg_id);
  protocol::wire::encodeFields(params, record, &frame[kParamsOffset]);
  frame.back() = xorChecksum(frame.data(), frame.size() - 1);
  return frame;
}

std::vector<uint8_t> buildSimpleCommand(uint8_t seq, MsgId msg_id) {
  return buildFrame(seq, msg_id, protocol::wire::listOf(kSimpleCommandParams), NoParams{});
}

}  // namespace

uint8_t xorChecksum(const uint8_t* data, std::size_t size) {
  uint8_t result = 0;
  for (std::size_t i = 0; i < size; ++i) result ^= data[i];
  return result;
}

std::vector<uint8_t> encodeWheelSpeed(uint8_t seq, int16_t left_ticks, int16_t right_ticks) {
  return buildFrame(seq, MsgId::kWheelSpeed, protocol::wire::listOf(kWheelSpeedParams),
                    WheelSpeed{left_ticks, right_ticks});
}

std::vector<uint8_t> encodeBatteryRequest(uint8_t seq) {
  return buildSimpleCommand(seq, MsgId::kBattery);
}

std::vector<uint8_t> encodeReset(uint8_t seq) { return buildSimpleCommand(seq, MsgId::kReset); }

std::vector<uint8_t> encodeClearEncoders(uint8_t seq) {
  return buildSimpleCommand(seq, MsgId::kClearEncoders);
}

std::vector<uint8_t> encodeErrorStatus(uint8_t seq) {
  return buildSimpleCommand(seq, MsgId::kErrorStatus);
}

std::vector<uint8_t> encodeBatteryReply(uint8_t seq, uint8_t percent) {
  return buildFrame(seq, MsgId::kBattery, protocol::wire::listOf(kBatteryReplyParams),
                    BatteryLevel{percent});
}

protocol::Probe probeFrame(const uint8_t* data, std::size_t available) {
  if (available < 1) return protocol::Probe::needMore();
  if (data[0] != kHeader0) return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  if (available < 2) return protocol::Probe::needMore();
  if (data[1] != kHeader1) return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  if (available <= kLenOffset) return protocol::Probe::needMore();
  const uint8_t len = data[kLenOffset];
  if (len < kMinLen || len > kMaxLen)
    return protocol::Probe::invalid(protocol::DecodeError::kBadLength);
  const std::size_t size = frameSize(len);
  if (available < size) return protocol::Probe::needMore();
  if (xorChecksum(data, size - 1) != data[size - 1]) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadChecksum);
  }
  return protocol::Probe::frame(size);
}

protocol::Decoded<Frame> decodeFrame(const uint8_t* data, std::size_t size) {
  if (size <= kLenOffset) return protocol::DecodeError::kTooShort;
  if (data[0] != kHeader0 || data[1] != kHeader1) return protocol::DecodeError::kBadHeader;
  const uint8_t len = data[kLenOffset];
  if (len < kMinLen || len > kMaxLen) return protocol::DecodeError::kBadLength;
  if (size < frameSize(len)) return protocol::DecodeError::kTooShort;
  if (size > frameSize(len)) return protocol::DecodeError::kBadLength;
  if (xorChecksum(data, size - 1) != data[size - 1]) return protocol::DecodeError::kBadChecksum;

  Frame frame;
  frame.seq = data[kSeqOffset];
  frame.msg_id = data[kMsgIdOffset];
  frame.param_count = static_cast<uint8_t>(len - 1);
  std::copy(data + kParamsOffset, data + kParamsOffset + frame.param_count, frame.params.begin());
  return frame;
}

protocol::Decoded<Reply> interpretReply(const Frame& frame) {
  Reply reply;
  reply.frame = frame;
  switch (frame.msg_id) {
    case static_cast<uint8_t>(MsgId::kErrorStatus):
      reply.kind = Reply::Kind::kTimeoutError;
      break;
    case static_cast<uint8_t>(MsgId::kBattery): {
      const auto params = protocol::wire::listOf(kBatteryReplyParams);
      if (frame.param_count < params.size()) return protocol::DecodeError::kUnexpectedContent;
      BatteryLevel level;
      protocol::wire::decodeFields(params, frame.params.data(), &level);
      reply.kind = Reply::Kind::kBattery;
      reply.battery_percent = std::min(level.percent, kMaxBatteryPercent);
      break;
    }
    default:
      // Unknown ids are counted and published raw by the device layer, never fatal.
      reply.kind = Reply::Kind::kUnknown;
      break;
  }
  return reply;
}

protocol::Decoded<WheelSpeed> interpretWheelSpeed(const Frame& frame) {
  const auto params = protocol::wire::listOf(kWheelSpeedParams);
  if (frame.msg_id != static_cast<uint8_t>(MsgId::kWheelSpeed) ||
      frame.param_count != params.size()) {
    return protocol::DecodeError::kUnexpectedContent;
  }
  WheelSpeed speed;
  protocol::wire::decodeFields(params, frame.params.data(), &speed);
  return speed;
}

static_assert(kMaxFrameSize <= protocol::StreamFramer::kLongestFrame,
              "base frame too long for the framer");

constexpr protocol::FrameFamily kFrames{
    "base", kHeader0,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeFrame(data, available);
    },
    0,
    [](const uint8_t* frame, std::size_t size, std::size_t) {
      const auto decoded = decodeFrame(frame, size);
      if (!decoded.ok()) return false;
      (void)interpretReply(*decoded);  // any PARAM: no throw, no read beyond it
      (void)interpretWheelSpeed(*decoded);
      return true;
    }};

}  // namespace serial_robot_driver::devices::base
