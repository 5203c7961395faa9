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

void FramerConfig::accept(FrameFamily family) {
  switch (family) {
    case FrameFamily::kBase:
      base = true;
      break;
    case FrameFamily::kTelemetry:
      telemetry = true;
      break;
    case FrameFamily::kServoResponse:
      servo_response = true;
      break;
    case FrameFamily::kServoRequest:
      servo_request = true;
      break;
    case FrameFamily::kSyncWrite:
      sync_write = true;
      break;
  }
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
  // Order matters only for the shared first byte 0x12: telemetry is asked before requests.
  if (config_.base) {
    addEntry(base::kHeader0, FrameFamily::kBase,
             [](const uint8_t* data, std::size_t available, std::size_t) {
               return base::probeFrame(data, available);
             });
  }
  if (config_.servo_response) {
    addEntry(servo::kResponseHeader0, FrameFamily::kServoResponse,
             [](const uint8_t* data, std::size_t available, std::size_t) {
               return servo::probeResponse(data, available);
             });
  }
  if (config_.sync_write) {
    addEntry(body::kSyncWriteHeader[0], FrameFamily::kSyncWrite,
             [](const uint8_t* data, std::size_t available, std::size_t) {
               return body::probeSyncWrite(data, available);
             });
  }
  if (config_.telemetry) {
    addEntry(body::kTelemetryHeader0, FrameFamily::kTelemetry,
             [](const uint8_t* data, std::size_t available, std::size_t servo_count) {
               return body::probeTelemetry(data, available, servo_count);
             });
  }
  if (config_.servo_request) {
    addEntry(servo::kRequestHeader0, FrameFamily::kServoRequest,
             [](const uint8_t* data, std::size_t available, std::size_t) {
               return servo::probeRequest(data, available);
             });
  }
  int start_count = 0;
  for (int byte = 0; byte < 256; ++byte) {
    if (!is_start_[byte]) continue;
    ++start_count;
    single_start_ = byte;
  }
  if (start_count != 1) single_start_ = -1;
}

void StreamFramer::addEntry(uint8_t header0, FrameFamily family,
                            Probe (*probe)(const uint8_t*, std::size_t, std::size_t)) {
  // Keep entries with the same first byte adjacent and in the order they were added.
  std::size_t at = entry_count_;
  for (std::size_t i = 0; i < entry_count_; ++i) {
    if (entries_[i].header0 == header0) at = i + 1;
  }
  std::move_backward(entries_.begin() + at, entries_.begin() + entry_count_,
                     entries_.begin() + entry_count_ + 1);
  entries_[at] = Entry{header0, family, probe};
  ++entry_count_;
  is_start_[header0] = true;
  first_entry_.fill(kNoEntry);
  for (std::size_t i = entry_count_; i-- > 0;)
    first_entry_[entries_[i].header0] = static_cast<uint8_t>(i);
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

bool StreamFramer::dropStaleCandidate() {
  if (size_ == 0) return false;
  ++stats_.stale_candidates;
  ++stats_.bytes_skipped;
  --size_;
  std::memmove(buffer_.data(), buffer_.data() + 1, size_);
  const std::size_t consumed = scan(buffer_.data(), size_, size_);
  std::memmove(buffer_.data(), buffer_.data() + consumed, size_ - consumed);
  size_ -= consumed;
  return true;
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

    FrameFamily family = FrameFamily::kBase;
    const Probe probe = examine(data + pos, available - pos, &family);
    switch (probe.status) {
      case Probe::Status::kFrame:
        ++stats_.frames[familyIndex(family)];
        if (handler_) handler_(family, data + pos, probe.size);
        pos += probe.size;
        break;
      case Probe::Status::kNeedMore:
        return pos;
      case Probe::Status::kInvalid:
        // Drop ONE byte only: a real frame may start inside the rejected candidate.
        ++stats_.bytes_skipped;
        ++pos;
        break;
    }
  }
  return pos;
}

Probe StreamFramer::examine(const uint8_t* data, std::size_t available, FrameFamily* family) {
  Probe result = Probe::invalid(DecodeError::kBadHeader);
  // Entries sharing a first byte are adjacent (addEntry keeps them so): start at the first one.
  for (std::size_t i = first_entry_[data[0]]; i < entry_count_; ++i) {
    const Entry& entry = entries_[i];
    if (entry.header0 != data[0]) break;
    result = entry.probe(data, available, config_.telemetry_servo_count);
    if (result.status == Probe::Status::kInvalid && result.reason == DecodeError::kBadHeader) {
      continue;
    }
    *family = entry.family;
    break;
  }
  if (result.status == Probe::Status::kInvalid) {
    switch (result.reason) {
      case DecodeError::kBadLength:
        ++stats_.bad_lengths;
        break;
      case DecodeError::kUnknownCommand:
        ++stats_.unknown_commands;
        break;
      case DecodeError::kBadChecksum:
        ++stats_.checksum_errors;
        break;
      case DecodeError::kBadTail:
        ++stats_.bad_tails;
        break;
      default:
        break;  // a header that is not ours is ordinary resynchronisation
    }
  }
  return result;
}

}  // namespace serial_robot_driver::protocol
