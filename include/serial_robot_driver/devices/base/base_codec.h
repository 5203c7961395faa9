// AP1 wheeled base protocol (docs/protocols.md, section 1).
//
//   55 AA | LEN | SEQ | MSGID | PARAM... | XOR
//
// LEN counts MSGID + PARAM; XOR covers every byte before it, header included. The same layout is
// used in both directions (the reply layout is an assumption of docs/protocols.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/protocol/decode_result.h"
#include "serial_robot_driver/protocol/frame_family.h"

namespace serial_robot_driver::devices::base {

constexpr uint8_t kHeader0 = 0x55;
constexpr uint8_t kHeader1 = 0xAA;
/// Bytes around MSGID+PARAM: header (2), LEN, SEQ, XOR.
constexpr std::size_t kOverhead = 5;
constexpr uint8_t kMinLen = 1;  ///< a frame carries at least its MSGID
/// Longest LEN accepted from the base. The vendor's longest frame has LEN 9; anything far above is
/// a corrupted length byte, and rejecting it early keeps the framer from stalling on 255-byte
/// waits. (assumption, one constant to change)
constexpr uint8_t kMaxLen = 32;
constexpr std::size_t kMaxFrameSize = kMaxLen + kOverhead;

enum class MsgId : uint8_t {
  kWheelSpeed = 0x01,
  kBattery = 0x02,  ///< host: battery request; base: battery reply, PARAM[0] = percent
  kReset = 0x05,
  kClearEncoders = 0x06,
  kErrorStatus = 0xFF,  ///< base: connection-timeout error status
};

/// Frame size for a given LEN byte.
constexpr std::size_t frameSize(uint8_t len) { return len + kOverhead; }

/// XOR of `size` bytes.
uint8_t xorChecksum(const uint8_t* data, std::size_t size);

/// Host sequence number: one per frame sent, wrapping 255 -> 0.
class SequenceCounter {
 public:
  uint8_t next() { return value_++; }
  uint8_t peek() const { return value_; }
  void reset(uint8_t value = 0) { value_ = value; }

 private:
  uint8_t value_ = 0;
};

/// Wheel speeds in encoder ticks per PID period (PARAM layout: base_codec.cpp, kWheelSpeedParams).
std::vector<uint8_t> encodeWheelSpeed(uint8_t seq, int16_t left_ticks, int16_t right_ticks);
std::vector<uint8_t> encodeBatteryRequest(uint8_t seq);
std::vector<uint8_t> encodeReset(uint8_t seq);
std::vector<uint8_t> encodeClearEncoders(uint8_t seq);

/// Any base frame, host->base or base->host, after header/LEN/XOR checks.
struct Frame {
  uint8_t seq = 0;
  uint8_t msg_id = 0;
  uint8_t param_count = 0;
  std::array<uint8_t, kMaxLen> params{};
};

/// Probes the `available` bytes at a stream position for a complete, verified frame: header,
/// LEN range and XOR (kBadHeader / kBadLength / kBadChecksum).
protocol::Probe probeFrame(const uint8_t* data, std::size_t available);
/// The base's frames (both directions share the layout): "base", 55 AA, XOR.
extern const protocol::FrameFamily kFrames;

/// Decodes one complete frame (exactly frameSize(LEN) bytes).
protocol::Decoded<Frame> decodeFrame(const uint8_t* data, std::size_t size);

/// What a frame from the base means to the driver.
struct Reply {
  enum class Kind { kTimeoutError, kBattery, kUnknown };
  Kind kind = Kind::kUnknown;
  uint8_t battery_percent = 0;  ///< valid for kBattery, clamped to 0..100
  Frame frame;                  ///< raw content, kept for kUnknown
};

/// Interprets a decoded base frame. A battery reply without a PARAM byte is kUnexpectedContent.
protocol::Decoded<Reply> interpretReply(const Frame& frame);

/// Host-side wheel speed content of a kWheelSpeed frame (used by the simulator and tests).
struct WheelSpeed {
  int16_t left_ticks = 0;
  int16_t right_ticks = 0;
};
protocol::Decoded<WheelSpeed> interpretWheelSpeed(const Frame& frame);

/// Base->host replies, for the simulator.
std::vector<uint8_t> encodeErrorStatus(uint8_t seq);
std::vector<uint8_t> encodeBatteryReply(uint8_t seq, uint8_t percent);

}  // namespace serial_robot_driver::devices::base
