#include "serial_robot_driver/protocol/stream_framer.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "serial_robot_driver/protocol/base_codec.h"
#include "serial_robot_driver/protocol/body_codec.h"
#include "serial_robot_driver/protocol/byte_order.h"
#include "serial_robot_driver/protocol/servo_bus_codec.h"

namespace serial_robot_driver::protocol {
namespace {

// Fixed offsets shared by the families' layouts (PROTOCOLS.md sections 1-3).
constexpr std::size_t kBaseLenOffset = 2;
constexpr std::size_t kTelemetryLenOffset = 2;
constexpr std::size_t kTelemetryTrailer = 3;  // SUM + tail
constexpr std::size_t kServoCmdOffset = 2;
constexpr std::size_t kServoSizeOffset = 3;
constexpr std::size_t kSyncWriteLenOffset = 5;
constexpr std::size_t kSyncWriteInstructionOffset = 7;
constexpr std::size_t kSyncWriteBytesPerServo = 3;
constexpr std::size_t kCrcSize = 2;

constexpr std::size_t kLongestSyncWrite =
    body::kSyncWritePrefix + body::syncWriteLen(body::kMaxSyncWriteServos);
static_assert(base::kMaxFrameSize <= StreamFramer::kLongestFrame, "base frame too long");
static_assert(servo::kMaxFrameSize <= StreamFramer::kLongestFrame, "servo frame too long");
static_assert(kLongestSyncWrite <= StreamFramer::kLongestFrame, "sync write too long");
// feed() keeps an incomplete candidate (< kLongestFrame bytes) and appends up to kLongestFrame.
static_assert(2 * StreamFramer::kLongestFrame <= StreamFramer::kBufferSize, "buffer too small");

std::size_t familyIndex(FrameFamily family) { return static_cast<std::size_t>(family); }

}  // namespace

const char* toString(FrameFamily family) {
  switch (family) {
    case FrameFamily::kBase:
      return "base";
    case FrameFamily::kTelemetry:
      return "telemetry";
    case FrameFamily::kServoResponse:
      return "servo_response";
    case FrameFamily::kServoRequest:
      return "servo_request";
    case FrameFamily::kSyncWrite:
      return "sync_write";
  }
  return "unknown";
}

FramerConfig FramerConfig::forDriver(bool base, bool body, bool servo_bus,
                                     std::size_t servo_count) {
  FramerConfig config;
  config.base = base;
  config.telemetry = body;
  config.servo_response = servo_bus;
  // The bus is half duplex: our own requests come back as an echo and must be framed (and then
  // ignored) rather than skipped byte by byte, or they could hide a response.
  config.servo_request = servo_bus;
  config.telemetry_servo_count = servo_count;
  return config;
}

FramerConfig FramerConfig::forSimulator() {
  FramerConfig config;
  config.base = true;
  config.servo_request = true;
  config.sync_write = true;
  return config;
}

StreamFramer::StreamFramer(const FramerConfig& config, FrameHandler handler)
    : config_(config), handler_(std::move(handler)) {
  if (config_.base) is_start_[base::kHeader0] = true;
  if (config_.telemetry) is_start_[body::kTelemetryHeader0] = true;
  if (config_.servo_response) is_start_[servo::kResponseHeader0] = true;
  if (config_.servo_request) is_start_[servo::kRequestHeader0] = true;
  if (config_.sync_write) is_start_[body::kSyncWriteHeader[0]] = true;
  int start_count = 0;
  for (int byte = 0; byte < 256; ++byte) {
    if (!is_start_[byte]) continue;
    ++start_count;
    single_start_ = byte;
  }
  if (start_count != 1) single_start_ = -1;
}

void StreamFramer::feed(const uint8_t* data, std::size_t size) {
  stats_.bytes_in += size;
  while (size > 0) {
    if (size_ == 0) {
      // Fast path: frames are found and handed out straight from the caller's chunk; only the
      // incomplete candidate at its end (shorter than kLongestFrame) is copied.
      const std::size_t consumed = scan(data, size, size);
      size_ = size - consumed;
      std::memcpy(buffer_.data(), data + consumed, size_);
      return;
    }
    // An incomplete candidate is pending. Append just enough bytes to settle it: a candidate that
    // starts in the old bytes ends at most kLongestFrame bytes later.
    const std::size_t pending = size_;
    const std::size_t appended = std::min(size, kLongestFrame);
    std::memcpy(buffer_.data() + size_, data, appended);
    size_ += appended;
    const std::size_t consumed = scan(buffer_.data(), size_, pending);
    if (consumed >= pending) {
      // Everything from the old bytes is settled; buffer_[pending + k] == data[k], so carry on in
      // the caller's chunk where the buffer scan stopped.
      const std::size_t used_from_chunk = consumed - pending;
      size_ = 0;
      data += used_from_chunk;
      size -= used_from_chunk;
    } else {
      // Still incomplete, which means the whole chunk fitted in `appended`: keep it all.
      std::memmove(buffer_.data(), buffer_.data() + consumed, size_ - consumed);
      size_ -= consumed;
      data += appended;
      size -= appended;
    }
  }
}

void StreamFramer::reset() {
  stats_.bytes_skipped += size_;
  size_ = 0;
}

std::size_t StreamFramer::findStart(const uint8_t* data, std::size_t from, std::size_t to) const {
  if (single_start_ >= 0) {
    const auto* found =
        static_cast<const uint8_t*>(std::memchr(data + from, single_start_, to - from));
    return found == nullptr ? to : static_cast<std::size_t>(found - data);
  }
  while (from < to && !is_start_[data[from]]) ++from;
  return from;
}

std::size_t StreamFramer::scan(const uint8_t* data, std::size_t available,
                               std::size_t start_limit) {
  std::size_t pos = 0;
  while (pos < start_limit) {
    const std::size_t start = findStart(data, pos, start_limit);
    stats_.bytes_skipped += start - pos;
    pos = start;
    if (pos >= start_limit) break;

    std::size_t frame_size = 0;
    FrameFamily family = FrameFamily::kBase;
    switch (examine(data + pos, available - pos, &frame_size, &family)) {
      case Candidate::kFrame:
        ++stats_.frames[familyIndex(family)];
        if (handler_) handler_(family, data + pos, frame_size);
        pos += frame_size;
        break;
      case Candidate::kNeedMore:
        return pos;
      case Candidate::kInvalid:
        // Drop ONE byte only: a real frame may start inside the rejected candidate.
        ++stats_.bytes_skipped;
        ++pos;
        break;
    }
  }
  return pos;
}

StreamFramer::Candidate StreamFramer::examine(const uint8_t* data, std::size_t available,
                                              std::size_t* frame_size, FrameFamily* family) {
  const uint8_t first = data[0];
  if (config_.base && first == base::kHeader0) {
    *family = FrameFamily::kBase;
    return examineBase(data, available, frame_size);
  }
  if (config_.servo_response && first == servo::kResponseHeader0) {
    *family = FrameFamily::kServoResponse;
    return examineServo(data, available, frame_size);
  }
  if (config_.sync_write && first == body::kSyncWriteHeader[0]) {
    *family = FrameFamily::kSyncWrite;
    return examineSyncWrite(data, available, frame_size);
  }
  // 0x12 starts both telemetry (12 34) and servo requests (12 4C): the second byte decides.
  static_assert(body::kTelemetryHeader0 == servo::kRequestHeader0, "shared first header byte");
  if (first == body::kTelemetryHeader0 && (config_.telemetry || config_.servo_request)) {
    if (available < 2) return Candidate::kNeedMore;
    if (config_.telemetry && data[1] == body::kTelemetryHeader1) {
      *family = FrameFamily::kTelemetry;
      return examineTelemetry(data, available, frame_size);
    }
    if (config_.servo_request && data[1] == servo::kRequestHeader1) {
      *family = FrameFamily::kServoRequest;
      return examineServo(data, available, frame_size);
    }
  }
  return Candidate::kInvalid;
}

StreamFramer::Candidate StreamFramer::examineBase(const uint8_t* data, std::size_t available,
                                                  std::size_t* frame_size) {
  if (available < 2) return Candidate::kNeedMore;
  if (data[1] != base::kHeader1) return Candidate::kInvalid;
  if (available <= kBaseLenOffset) return Candidate::kNeedMore;
  const uint8_t len = data[kBaseLenOffset];
  if (len < base::kMinLen || len > base::kMaxLen) {
    ++stats_.bad_lengths;
    return Candidate::kInvalid;
  }
  const std::size_t size = base::frameSize(len);
  if (available < size) return Candidate::kNeedMore;
  if (base::xorChecksum(data, size - 1) != data[size - 1]) {
    ++stats_.checksum_errors;
    return Candidate::kInvalid;
  }
  *frame_size = size;
  return Candidate::kFrame;
}

StreamFramer::Candidate StreamFramer::examineTelemetry(const uint8_t* data, std::size_t available,
                                                       std::size_t* frame_size) {
  // Header already matched by examine().
  if (available <= kTelemetryLenOffset) return Candidate::kNeedMore;
  const std::size_t len = data[kTelemetryLenOffset];
  const std::size_t servo_count = config_.telemetry_servo_count;
  if (len != body::telemetryLen(servo_count, false) &&
      len != body::telemetryLen(servo_count, true)) {
    ++stats_.bad_lengths;
    return Candidate::kInvalid;
  }
  if (available < len) return Candidate::kNeedMore;
  // Tail first: a wrong tail means the frame boundary itself is wrong.
  if (data[len - 2] != body::kTelemetryTail0 || data[len - 1] != body::kTelemetryTail1) {
    ++stats_.bad_tails;
    return Candidate::kInvalid;
  }
  if (body::telemetrySum(data, len) != data[len - kTelemetryTrailer]) {
    ++stats_.checksum_errors;
    return Candidate::kInvalid;
  }
  *frame_size = len;
  return Candidate::kFrame;
}

StreamFramer::Candidate StreamFramer::examineServo(const uint8_t* data, std::size_t available,
                                                   std::size_t* frame_size) {
  // Requests and responses share the layout; examine() picked the family from the first byte.
  const uint8_t header1 =
      data[0] == servo::kResponseHeader0 ? servo::kResponseHeader1 : servo::kRequestHeader1;
  if (available < 2) return Candidate::kNeedMore;
  if (data[1] != header1) return Candidate::kInvalid;
  if (available <= kServoSizeOffset) return Candidate::kNeedMore;
  const uint8_t cmd = data[kServoCmdOffset];
  const uint8_t content_size = data[kServoSizeOffset];
  if (cmd < servo::kMinCommand || cmd > servo::kMaxCommand || content_size > servo::kMaxContent) {
    ++stats_.bad_lengths;
    return Candidate::kInvalid;
  }
  const std::size_t size = content_size + servo::kOverhead;
  if (available < size) return Candidate::kNeedMore;
  if (servo::byteSum(data, size - 1) != data[size - 1]) {
    ++stats_.checksum_errors;
    return Candidate::kInvalid;
  }
  *frame_size = size;
  return Candidate::kFrame;
}

StreamFramer::Candidate StreamFramer::examineSyncWrite(const uint8_t* data, std::size_t available,
                                                       std::size_t* frame_size) {
  // FF FF FD 00 then the broadcast id FE: compare as much of this prefix as has arrived.
  const std::size_t header_size = body::kSyncWriteHeader.size();
  const std::size_t known = std::min(available, header_size + 1);
  for (std::size_t i = 1; i < known; ++i) {
    const uint8_t expected = i < header_size ? body::kSyncWriteHeader[i] : body::kBroadcastId;
    if (data[i] != expected) return Candidate::kInvalid;
  }
  if (available < body::kSyncWritePrefix) return Candidate::kNeedMore;
  const std::size_t len = readLE16(data + kSyncWriteLenOffset);
  const std::size_t min_len = body::syncWriteLen(0);
  if (len < min_len || (len - min_len) % kSyncWriteBytesPerServo != 0 ||
      (len - min_len) / kSyncWriteBytesPerServo > body::kMaxSyncWriteServos) {
    ++stats_.bad_lengths;
    return Candidate::kInvalid;
  }
  if (available <= kSyncWriteInstructionOffset) return Candidate::kNeedMore;
  if (data[kSyncWriteInstructionOffset] != body::kSyncWriteInstruction) return Candidate::kInvalid;
  const std::size_t size = body::kSyncWritePrefix + len;
  if (available < size) return Candidate::kNeedMore;
  if (body::dynamixelCrc(data, size - kCrcSize) != readLE16(data + size - kCrcSize)) {
    ++stats_.checksum_errors;
    return Candidate::kInvalid;
  }
  *frame_size = size;
  return Candidate::kFrame;
}

}  // namespace serial_robot_driver::protocol
