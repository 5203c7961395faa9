// The echo device's frames: a loop-back used by the tests to show that a device is a folder and
// one registration line. The host sends a request, the device answers with the same payload.
//
//   request (host -> device): E5 01 LEN payload[LEN] XOR
//   answer  (device -> host): E5 02 LEN payload[LEN] XOR
//
// LEN counts the payload (0..kMaxPayload); XOR is the XOR of every byte before it. 0xE5 starts no
// other family (0x55, 0x12, 0x05 and 0xFF are taken).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/protocol/decode_result.h"
#include "serial_robot_driver/protocol/frame_family.h"

namespace serial_robot_driver::devices::echo {

constexpr uint8_t kHeader = 0xE5;
constexpr uint8_t kRequestType = 0x01;
constexpr uint8_t kAnswerType = 0x02;
constexpr std::size_t kMaxPayload = 32;
/// Header, type, LEN and XOR around the payload.
constexpr std::size_t kOverhead = 4;

/// A whole frame of `type` around `payload`; empty when the payload is longer than kMaxPayload.
std::vector<uint8_t> encode(uint8_t type, const std::vector<uint8_t>& payload);
inline std::vector<uint8_t> encodeRequest(const std::vector<uint8_t>& payload) {
  return encode(kRequestType, payload);
}
inline std::vector<uint8_t> encodeAnswer(const std::vector<uint8_t>& payload) {
  return encode(kAnswerType, payload);
}

/// Probes for a complete frame of `type`: kBadHeader (another header or type: not ours),
/// kBadLength (LEN > kMaxPayload), kBadChecksum.
protocol::Probe probe(uint8_t type, const uint8_t* data, std::size_t available);
/// A complete frame of `type` back into its payload (header, LEN and XOR checked).
protocol::Decoded<std::vector<uint8_t>> decode(uint8_t type, const uint8_t* data, std::size_t size);

/// Requests (what the simulated device reads): "echo_request".
extern const protocol::FrameFamily kRequestFrames;
/// Answers (what the driver reads): "echo_answer".
extern const protocol::FrameFamily kAnswerFrames;

}  // namespace serial_robot_driver::devices::echo
