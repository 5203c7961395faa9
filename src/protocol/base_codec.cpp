#include "serial_robot_driver/protocol/base_codec.h"

#include <algorithm>
#include "serial_robot_driver/protocol/stream_framer.h"

#include "serial_robot_driver/protocol/byte_order.h"

namespace serial_robot_driver::protocol::base {

namespace {

constexpr uint8_t kWheelSpeedLen = 9;  // MSGID + 2 x int16 + 4 zero bytes
constexpr uint8_t kMaxBatteryPercent = 100;

// Builds 55 AA | LEN | SEQ | MSGID | PARAM... | XOR.
std::vector<uint8_t> buildFrame(uint8_t seq, MsgId msg_id, const uint8_t* params,
                                std::size_t param_count) {
  std::vector<uint8_t> frame;
  frame.reserve(param_count + 1 + kOverhead);
  frame.push_back(kHeader0);
  frame.push_back(kHeader1);
  frame.push_back(static_cast<uint8_t>(param_count + 1));
  frame.push_back(seq);
  frame.push_back(static_cast<uint8_t>(msg_id));
  frame.insert(frame.end(), params, params + param_count);
  frame.push_back(xorChecksum(frame.data(), frame.size()));
  return frame;
}

// The vendor's one-byte commands all carry a single 00 parameter (LEN 2).
std::vector<uint8_t> buildSimpleCommand(uint8_t seq, MsgId msg_id) {
  const uint8_t param = 0x00;
  return buildFrame(seq, msg_id, &param, 1);
}

}  // namespace

uint8_t xorChecksum(const uint8_t* data, std::size_t size) {
  uint8_t result = 0;
  for (std::size_t i = 0; i < size; ++i) result ^= data[i];
  return result;
}

std::vector<uint8_t> encodeWheelSpeed(uint8_t seq, int16_t left_ticks, int16_t right_ticks) {
  std::array<uint8_t, kWheelSpeedLen - 1> params{};  // trailing 4 bytes stay zero
  writeBE16(&params[0], static_cast<uint16_t>(left_ticks));
  writeBE16(&params[2], static_cast<uint16_t>(right_ticks));
  return buildFrame(seq, MsgId::kWheelSpeed, params.data(), params.size());
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
  return buildFrame(seq, MsgId::kBattery, &percent, 1);
}

Probe probeFrame(const uint8_t* data, std::size_t available) {
  constexpr std::size_t kLenOffset = 2;
  if (available < 1) return Probe::needMore();
  if (data[0] != kHeader0) return Probe::invalid(DecodeError::kBadHeader);
  if (available < 2) return Probe::needMore();
  if (data[1] != kHeader1) return Probe::invalid(DecodeError::kBadHeader);
  if (available <= kLenOffset) return Probe::needMore();
  const uint8_t len = data[kLenOffset];
  if (len < kMinLen || len > kMaxLen) return Probe::invalid(DecodeError::kBadLength);
  const std::size_t size = frameSize(len);
  if (available < size) return Probe::needMore();
  if (xorChecksum(data, size - 1) != data[size - 1]) {
    return Probe::invalid(DecodeError::kBadChecksum);
  }
  return Probe::frame(size);
}

Decoded<Frame> decodeFrame(const uint8_t* data, std::size_t size) {
  constexpr std::size_t kLenOffset = 2;
  if (size <= kLenOffset) return DecodeError::kTooShort;
  if (data[0] != kHeader0 || data[1] != kHeader1) return DecodeError::kBadHeader;
  const uint8_t len = data[kLenOffset];
  if (len < kMinLen || len > kMaxLen) return DecodeError::kBadLength;
  if (size < frameSize(len)) return DecodeError::kTooShort;
  if (size > frameSize(len)) return DecodeError::kBadLength;
  if (xorChecksum(data, size - 1) != data[size - 1]) return DecodeError::kBadChecksum;

  Frame frame;
  frame.seq = data[3];
  frame.msg_id = data[4];
  frame.param_count = static_cast<uint8_t>(len - 1);
  std::copy(data + 5, data + 5 + frame.param_count, frame.params.begin());
  return frame;
}

Decoded<Reply> interpretReply(const Frame& frame) {
  Reply reply;
  reply.frame = frame;
  switch (frame.msg_id) {
    case static_cast<uint8_t>(MsgId::kErrorStatus):
      reply.kind = Reply::Kind::kTimeoutError;
      break;
    case static_cast<uint8_t>(MsgId::kBattery):
      if (frame.param_count < 1) return DecodeError::kUnexpectedContent;
      reply.kind = Reply::Kind::kBattery;
      reply.battery_percent = std::min(frame.params[0], kMaxBatteryPercent);
      break;
    default:
      // Unknown ids are counted and published raw by the device layer, never fatal.
      reply.kind = Reply::Kind::kUnknown;
      break;
  }
  return reply;
}

Decoded<WheelSpeed> interpretWheelSpeed(const Frame& frame) {
  if (frame.msg_id != static_cast<uint8_t>(MsgId::kWheelSpeed) ||
      frame.param_count != kWheelSpeedLen - 1) {
    return DecodeError::kUnexpectedContent;
  }
  WheelSpeed speed;
  speed.left_ticks = readBE16Signed(&frame.params[0]);
  speed.right_ticks = readBE16Signed(&frame.params[2]);
  return speed;
}

static_assert(kMaxFrameSize <= StreamFramer::kLongestFrame, "base frame too long for the framer");

constexpr FrameFamily kFrames{
    "base", kHeader0,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probeFrame(data, available);
    },
    0};

}  // namespace serial_robot_driver::protocol::base
