#include "serial_robot_driver/devices/echo/echo_codec.h"

namespace serial_robot_driver::devices::echo {

namespace {

uint8_t xorOf(const uint8_t* data, std::size_t size) {
  uint8_t check = 0;
  for (std::size_t i = 0; i < size; ++i) check ^= data[i];
  return check;
}

constexpr std::size_t kTypeOffset = 1;
constexpr std::size_t kLenOffset = 2;
constexpr std::size_t kPayloadOffset = 3;

}  // namespace

std::vector<uint8_t> encode(uint8_t type, const std::vector<uint8_t>& payload) {
  if (payload.size() > kMaxPayload) return {};
  std::vector<uint8_t> frame{kHeader, type, static_cast<uint8_t>(payload.size())};
  frame.insert(frame.end(), payload.begin(), payload.end());
  frame.push_back(xorOf(frame.data(), frame.size()));
  return frame;
}

protocol::Probe probe(uint8_t type, const uint8_t* data, std::size_t available) {
  if (available > 0 && data[0] != kHeader)
    return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  // The other direction's frames share the header: not ours, and not an error.
  if (available > kTypeOffset && data[kTypeOffset] != type) {
    return protocol::Probe::invalid(protocol::DecodeError::kBadHeader);
  }
  if (available <= kLenOffset) return protocol::Probe::needMore();
  const std::size_t len = data[kLenOffset];
  if (len > kMaxPayload) return protocol::Probe::invalid(protocol::DecodeError::kBadLength);
  const std::size_t size = kOverhead + len;
  if (available < size) return protocol::Probe::needMore();
  if (xorOf(data, size - 1) != data[size - 1])
    return protocol::Probe::invalid(protocol::DecodeError::kBadChecksum);
  return protocol::Probe::frame(size);
}

protocol::Decoded<std::vector<uint8_t>> decode(uint8_t type, const uint8_t* data,
                                               std::size_t size) {
  const protocol::Probe found = probe(type, data, size);
  if (found.status == protocol::Probe::Status::kNeedMore) return protocol::DecodeError::kTooShort;
  if (found.status == protocol::Probe::Status::kInvalid) return found.reason;
  if (found.size != size) return protocol::DecodeError::kBadLength;
  return std::vector<uint8_t>(data + kPayloadOffset, data + size - 1);
}

// Requests first: the two families share the header, the type byte tells them apart.
constexpr protocol::FrameFamily kRequestFrames{
    "echo_request", kHeader,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probe(kRequestType, data, available);
    },
    0,
    [](const uint8_t* frame, std::size_t size, std::size_t) {
      return decode(kRequestType, frame, size).ok();
    }};
constexpr protocol::FrameFamily kAnswerFrames{
    "echo_answer", kHeader,
    [](const uint8_t* data, std::size_t available, std::size_t) {
      return probe(kAnswerType, data, available);
    },
    1,
    [](const uint8_t* frame, std::size_t size, std::size_t) {
      return decode(kAnswerType, frame, size).ok();
    }};

}  // namespace serial_robot_driver::devices::echo
