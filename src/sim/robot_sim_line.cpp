#include "robot_sim_line.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <random>

namespace serial_robot_driver::sim::detail {

namespace {

constexpr std::size_t kMaxGarbageBurst = 24;
/// With --pace-baud, a long frame goes into the pty in pieces of what the line carries in this
/// much time: a finer slice would only wake the simulator more often. A shorter frame goes in
/// whole once its last bit is through the line, as a UART reader would see it complete.
constexpr auto kPaceSlice = std::chrono::milliseconds(2);

/// Index of the checksum byte a corruption flips (the kind says where its checksum is).
std::size_t checksumIndex(const OutputKind& kind, std::size_t size) {
  return size >= kind.checksum_from_end ? size - kind.checksum_from_end : size - 1;
}

}  // namespace

Line::Line(const SimOptions& options, SimStats& counters)
    : options_(options), counters_(counters) {}

void Line::send(Port* port, Outgoing frame) {
  SendCounters& counters = sendCounters(counters_, frame.kind);
  if (port == nullptr || !port->plugged || port->draining || frame.bytes.empty()) {
    ++counters.discarded;
    return;
  }
  const FaultOptions& faults = options_.faults;
  std::uniform_real_distribution<double> chance(0.0, 1.0);
  bool damaged = false;
  std::vector<uint8_t>& bytes = frame.bytes;
  if (frame.garble_or_suppress_rate > 0 && chance(port->rng) < frame.garble_or_suppress_rate) {
    if (chance(port->rng) < 0.5) {
      ++counters.suppressed;
      return;
    }
    const std::size_t index =
        std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(port->rng);
    bytes[index] ^= static_cast<uint8_t>(std::uniform_int_distribution<int>(1, 255)(port->rng));
    damaged = true;
  }
  if (faults.corrupt_rate > 0 && chance(port->rng) < faults.corrupt_rate) {
    bytes[checksumIndex(*frame.kind, bytes.size())] ^= 0xFF;
    damaged = true;
  }
  if (faults.drop_rate > 0 && chance(port->rng) < faults.drop_rate) {
    const std::size_t index =
        std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(port->rng);
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(index));
    damaged = true;
  }
  if (port->backlog_bytes + bytes.size() > kMaxBacklogBytes) {
    ++counters.discarded;
    return;
  }
  port->backlog_bytes += bytes.size();
  const TimePoint ready_at = frame.ready_at == TimePoint{} ? Clock::now() : frame.ready_at;
  port->backlog.push_back(
      Port::PendingWrite{std::move(bytes), 0, true, frame.kind, damaged, ready_at});
  flush(port);
}

Clock::duration Line::lineTime(std::size_t bytes) const {
  return std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(10.0 * static_cast<double>(bytes) / options_.pace_baud));
}

TimePoint Line::nextSendAt(const Port* port) const {
  if (port->backlog.empty()) return TimePoint::max();
  const Port::PendingWrite& pending = port->backlog.front();
  const TimePoint line_start = std::max(port->tx_line_free, pending.ready_at);
  const std::size_t slice_bytes = std::max<std::size_t>(
      1, static_cast<std::size_t>(options_.pace_baud / 10.0 *
                                  std::chrono::duration<double>(kPaceSlice).count()));
  return line_start + lineTime(std::min(pending.bytes.size() - pending.offset, slice_bytes));
}

void Line::flush(Port* port) {
  if (port->dataFd() < 0) return;
  const bool paced = options_.pace_baud > 0;
  const TimePoint now = paced ? Clock::now() : TimePoint{};
  while (!port->backlog.empty()) {
    Port::PendingWrite& pending = port->backlog.front();
    std::size_t remaining = pending.bytes.size() - pending.offset;
    TimePoint line_start{};
    if (paced) {
      // Paced: once the next slice (or the whole of a short frame) is through, the bytes whose
      // last bit is through the line by now (the line carries a frame from when it is ready,
      // after what it carried before). A late wake-up delivers late but never stretches the
      // line: tx_line_free follows the line's own clock, not this thread's.
      if (now < nextSendAt(port)) return;
      line_start = std::max(port->tx_line_free, pending.ready_at);
      const auto through = static_cast<std::size_t>((now - line_start) / lineTime(1));
      remaining = std::min(remaining, through);
      if (remaining == 0) return;
    }
    const ssize_t written = port->writeSome(pending.bytes.data() + pending.offset, remaining);
    if (written < 0) {
      if (errno == EINTR) continue;
      return;  // EAGAIN: the host is not reading right now; retry when poll says writable
    }
    if (paced) port->tx_line_free = line_start + lineTime(static_cast<std::size_t>(written));
    counters_.bytes_sent += static_cast<uint64_t>(written);
    port->backlog_bytes -= static_cast<std::size_t>(written);
    pending.offset += static_cast<std::size_t>(written);
    if (pending.offset < pending.bytes.size()) continue;
    if (pending.is_frame) {
      SendCounters& counters = sendCounters(counters_, pending.kind);
      ++(pending.damaged ? counters.damaged : counters.intact);
    }
    port->backlog.pop_front();
  }
}

void Line::scheduleGarbage(Port* port, TimePoint now) {
  if (options_.faults.garbage_rate_hz <= 0) return;
  std::exponential_distribution<double> gap(options_.faults.garbage_rate_hz);
  port->next_garbage = now + fromSeconds(gap(port->rng));
}

void Line::injectGarbage(Port* port, TimePoint now) {
  if (now < port->next_garbage) return;
  std::exponential_distribution<double> gap(options_.faults.garbage_rate_hz);
  port->next_garbage = now + fromSeconds(gap(port->rng));
  if (!port->plugged || port->draining) return;
  const std::size_t length =
      std::uniform_int_distribution<std::size_t>(1, kMaxGarbageBurst)(port->rng);
  Port::PendingWrite junk;
  junk.is_frame = false;
  junk.ready_at = now;
  for (std::size_t i = 0; i < length; ++i) {
    junk.bytes.push_back(
        static_cast<uint8_t>(std::uniform_int_distribution<int>(0, 255)(port->rng)));
  }
  if (port->backlog_bytes + length > kMaxBacklogBytes) return;
  port->backlog_bytes += length;
  port->backlog.push_back(std::move(junk));
  ++counters_.garbage_bursts;
  counters_.garbage_bytes += length;
}

void Line::receive(Port* port, const uint8_t* data, std::size_t size, TimePoint read_at) {
  if (options_.pace_baud == 0) {
    port->framer->feed(data, size);
    return;
  }
  port->rx_line_free = std::max(port->rx_line_free, read_at) + lineTime(size);
  port->rx_in_flight.emplace_back(port->rx_line_free, std::vector<uint8_t>(data, data + size));
}

void Line::deliverArrived(Port* port, TimePoint now) {
  while (!port->rx_in_flight.empty() && port->rx_in_flight.front().first <= now) {
    const std::vector<uint8_t> bytes = std::move(port->rx_in_flight.front().second);
    port->rx_frame_end = port->rx_in_flight.front().first;
    port->rx_in_flight.pop_front();
    port->framer->feed(bytes.data(), bytes.size());
    port->rx_frame_end = TimePoint{};
  }
}

TimePoint Line::nextEvent(const Port& port) const {
  TimePoint next = port.next_garbage;
  if (options_.pace_baud > 0) next = std::min(next, nextSendAt(&port));
  if (!port.rx_in_flight.empty()) next = std::min(next, port.rx_in_flight.front().first);
  return next;
}

}  // namespace serial_robot_driver::sim::detail
