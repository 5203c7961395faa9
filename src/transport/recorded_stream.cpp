#include "serial_robot_driver/transport/recorded_stream.h"

#include <algorithm>
#include <cstring>
#include <thread>

namespace serial_robot_driver::transport {

ReplayPacing::ReplayPacing(double rate, SteadyTime first_arrival)
    : rate_(rate), first_arrival_(first_arrival), start_(std::chrono::steady_clock::now()) {}

SteadyTime ReplayPacing::dueAt(SteadyTime arrival) const {
  if (rate_ <= 0) return start_;
  const std::chrono::duration<double> recorded_offset = arrival - first_arrival_;
  return start_ +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(recorded_offset / rate_);
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

std::size_t RecordedStream::read(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  RecordedPort& port = *port_;
  const auto timeout = std::chrono::milliseconds(timeout_ms);
  if (port.next_ >= port.chunks_.size()) {
    port.finished_ = true;
    std::this_thread::sleep_for(timeout);
    return 0;
  }
  const RecordedChunk& chunk = port.chunks_[port.next_];
  if (chunk.data.empty()) {
    throw TransportError(TransportErrorKind::kDisconnected,
                         "the recording reopens port " + port.name_ + " here");
  }
  const SteadyTime due = port.pacing_->dueAt(chunk.arrival);
  if (due > std::chrono::steady_clock::now() + timeout) {
    std::this_thread::sleep_for(timeout);
    return 0;
  }
  std::this_thread::sleep_until(due);
  const std::size_t n = std::min(capacity, chunk.data.size() - port.offset_);
  std::memcpy(buffer, chunk.data.data() + port.offset_, n);
  arrival_ = chunk.arrival;
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
