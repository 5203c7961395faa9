#include "serial_robot_driver/protocol/stream_framer.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace serial_robot_driver::protocol {

// feed() keeps an incomplete candidate (< kLongestFrame bytes) and appends up to kLongestFrame.
static_assert(2 * StreamFramer::kLongestFrame <= StreamFramer::kBufferSize, "buffer too small");

void FramerConfig::accept(const FrameFamily& family, std::size_t expected) {
  for (std::size_t i = 0; i < family_count; ++i) {
    if (families[i].family == family) {
      families[i].expected = expected;
      return;
    }
  }
  if (family_count == families.size()) {
    throw std::length_error(std::string("a framer accepts at most ") +
                            std::to_string(families.size()) + " frame families");
  }
  families[family_count++] = Accepted{family, expected};
}

bool FramerConfig::accepts(const FrameFamily& family) const {
  for (std::size_t i = 0; i < family_count; ++i) {
    if (families[i].family == family) return true;
  }
  return false;
}

std::size_t FramerConfig::expectedOf(const FrameFamily& family) const {
  for (std::size_t i = 0; i < family_count; ++i) {
    if (families[i].family == family) return families[i].expected;
  }
  return 0;
}

uint64_t FramerStats::framesOf(const FrameFamily& family) const {
  for (std::size_t i = 0; i < family_count; ++i) {
    if (by_family[i].family == family.name) return by_family[i].frames;
  }
  return 0;
}

void FramerStats::add(const FramerStats& other) {
  bytes_in += other.bytes_in;
  bytes_skipped += other.bytes_skipped;
  checksum_errors += other.checksum_errors;
  bad_tails += other.bad_tails;
  bad_lengths += other.bad_lengths;
  unknown_commands += other.unknown_commands;
  stale_candidates += other.stale_candidates;
  for (std::size_t k = 0; k < other.family_count; ++k) {
    std::size_t i = 0;
    while (i < family_count && by_family[i].family != other.by_family[k].family) ++i;
    if (i == family_count) {
      if (family_count == by_family.size()) continue;  // cannot happen: both come from framers
      by_family[family_count++].family = other.by_family[k].family;
    }
    by_family[i].frames += other.by_family[k].frames;
  }
}

StreamFramer::StreamFramer(const FramerConfig& config, FrameHandler handler)
    : config_(config), handler_(std::move(handler)) {
  // Entries that share a first byte are asked in rank order (telemetry before servo requests).
  std::array<FramerConfig::Accepted, kMaxFamiliesPerFramer> by_rank = config_.families;
  std::stable_sort(by_rank.begin(), by_rank.begin() + config_.family_count,
                   [](const FramerConfig::Accepted& a, const FramerConfig::Accepted& b) {
                     return a.family.rank < b.family.rank;
                   });
  for (std::size_t i = 0; i < config_.family_count; ++i) {
    stats_.by_family[i].family = config_.families[i].family.name;
  }
  stats_.family_count = config_.family_count;
  for (std::size_t k = 0; k < config_.family_count; ++k) {
    std::size_t stats_index = 0;
    while (!(config_.families[stats_index].family == by_rank[k].family)) ++stats_index;
    addEntry(by_rank[k], stats_index);
  }
  int start_count = 0;
  for (int byte = 0; byte < 256; ++byte) {
    if (!is_start_[byte]) continue;
    ++start_count;
    single_start_ = byte;
  }
  if (start_count != 1) single_start_ = -1;
}

void StreamFramer::addEntry(const FramerConfig::Accepted& accepted, std::size_t stats_index) {
  const uint8_t header0 = accepted.family.header0;
  // Keep entries with the same first byte adjacent and in the order they were added.
  std::size_t at = entry_count_;
  for (std::size_t i = 0; i < entry_count_; ++i) {
    if (entries_[i].accepted.family.header0 == header0) at = i + 1;
  }
  std::move_backward(entries_.begin() + at, entries_.begin() + entry_count_,
                     entries_.begin() + entry_count_ + 1);
  entries_[at] = Entry{accepted, stats_index};
  ++entry_count_;
  is_start_[header0] = true;
  first_entry_.fill(kNoEntry);
  for (std::size_t i = entry_count_; i-- > 0;)
    first_entry_[entries_[i].accepted.family.header0] = static_cast<uint8_t>(i);
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

    const Entry* entry = nullptr;
    const Probe probe = examine(data + pos, available - pos, &entry);
    switch (probe.status) {
      case Probe::Status::kFrame:
        ++stats_.by_family[entry->stats_index].frames;
        if (handler_) handler_(entry->accepted.family, data + pos, probe.size);
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

Probe StreamFramer::examine(const uint8_t* data, std::size_t available, const Entry** found) {
  Probe result = Probe::invalid(DecodeError::kBadHeader);
  // Entries sharing a first byte are adjacent (addEntry keeps them so): start at the first one.
  for (std::size_t i = first_entry_[data[0]]; i < entry_count_; ++i) {
    const Entry& entry = entries_[i];
    if (entry.accepted.family.header0 != data[0]) break;
    result = entry.accepted.family.probe(data, available, entry.accepted.expected);
    if (result.status == Probe::Status::kInvalid && result.reason == DecodeError::kBadHeader) {
      continue;
    }
    *found = &entry;
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
