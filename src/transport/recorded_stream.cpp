#include "serial_robot_driver/transport/recorded_stream.h"

#include <algorithm>
#include <cstring>
#include <thread>

namespace serial_robot_driver::transport {

ReplayPacing::ReplayPacing(double rate, RecordedStamp first, RecordedStamp end)
    : rate_(rate), first_(first), end_(std::max(first, end)), start_(std::chrono::steady_clock::now()) {}

SteadyTime ReplayPacing::now() const {
  const auto since_start = std::chrono::steady_clock::now() - start_;
  return start_ + std::chrono::duration_cast<std::chrono::nanoseconds>(since_start * rate_);
}

std::chrono::nanoseconds ReplayPacing::steadyWait(std::chrono::nanoseconds span) const {
  if (rate_ <= 0 || span.count() <= 0) return std::chrono::nanoseconds(0);
  return std::chrono::duration_cast<std::chrono::nanoseconds>(span / rate_);
}

RecordedPort::RecordedPort(std::string name, std::vector<RecordedChunk> chunks,
                           std::shared_ptr<const ReplayPacing> pacing)
    : name_(std::move(name)), chunks_(std::move(chunks)), pacing_(std::move(pacing)) {}

RecordedPortStats RecordedPort::stats() const {
  RecordedPortStats s;
  s.chunks_fed = chunks_fed_;
  s.bytes_fed = bytes_fed_;
  s.reopens = reopens_;
  s.writes_discarded = writes_discarded_;
  s.bytes_discarded = bytes_discarded_;
  return s;
}

void RecordedStream::open() {
  RecordedPort& port = *port_;
  if (port.next_ < port.chunks_.size() && port.chunks_[port.next_].data.empty()) ++port.next_;
  ++port.reopens_;
  open_ = true;
}

SteadyTime RecordedStream::now() const {
  const RecordedPort& port = *port_;
  const ReplayPacing& pacing = *port.pacing_;
  if (port.next_ >= port.chunks_.size()) return pacing.paced() ? pacing.now() : pacing.end();
  const RecordedChunk& next = port.chunks_[port.next_];
  // Before a recorded reopen the port was lost right after its last bytes (read() throws at
  // once, as the live read did), not after a silence that a stale-frame timer could count.
  if (next.data.empty() && arrival_) return *arrival_;
  // The timeline never runs past bytes not yet read (live, the reader had them by then), so a
  // stale-frame timer decides as it did live however late a paced replay's thread runs.
  const SteadyTime next_arrival = pacing.onTimeline(next.recorded);
  return pacing.paced() ? std::min(pacing.now(), next_arrival) : next_arrival;
}

std::size_t RecordedStream::read(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  RecordedPort& port = *port_;
  const ReplayPacing& pacing = *port.pacing_;
  const std::chrono::nanoseconds timeout = std::chrono::milliseconds(std::max(timeout_ms, 0));
  if (port.next_ >= port.chunks_.size()) {
    // The recording may go on in silence after the last chunk: the replay ends with it.
    const SteadyTime now_on_timeline = now();
    if (now_on_timeline < pacing.end()) {
      std::this_thread::sleep_for(pacing.steadyWait(std::min(timeout, pacing.end() - now_on_timeline)));
      return 0;
    }
    port.finished_ = true;
    std::this_thread::sleep_for(pacing.paced() ? pacing.steadyWait(timeout) : timeout);
    return 0;
  }
  const RecordedChunk& chunk = port.chunks_[port.next_];
  if (chunk.data.empty()) {
    throw TransportError(TransportErrorKind::kDisconnected,
                         "the recording reopens port " + port.name_ + " here");
  }
  const SteadyTime arrival = pacing.onTimeline(chunk.recorded);
  if (pacing.paced()) {
    const SteadyTime now_on_timeline = pacing.now();
    if (arrival > now_on_timeline + timeout) {
      std::this_thread::sleep_for(pacing.steadyWait(timeout));
      return 0;
    }
    std::this_thread::sleep_for(pacing.steadyWait(arrival - now_on_timeline));
  }
  const std::size_t n = std::min(capacity, chunk.data.size() - port.offset_);
  std::memcpy(buffer, chunk.data.data() + port.offset_, n);
  arrival_ = arrival;
  port.offset_ += n;
  port.bytes_fed_ += n;
  if (port.offset_ == chunk.data.size()) {
    port.offset_ = 0;
    ++port.next_;
    ++port.chunks_fed_;
  }
  return n;
}

void RecordedStream::write(const uint8_t* /*data*/, std::size_t size) {
  ++port_->writes_discarded_;
  port_->bytes_discarded_ += size;
}

}  // namespace serial_robot_driver::transport
