#include "polling_stream.h"

#include <thread>

namespace serial_robot_driver::bench {

PollingStream::PollingStream(std::unique_ptr<transport::ByteStream> inner, double interval)
    : inner_(std::move(inner)),
      period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(interval))) {}

void PollingStream::open() {
  inner_->open();
  next_poll_ = std::chrono::steady_clock::now();
}

std::size_t PollingStream::read(uint8_t* buffer, std::size_t capacity, int /*timeout_ms*/) {
  // Absolute poll instants: the period does not drift with the time spent handling a chunk.
  next_poll_ += period_;
  std::this_thread::sleep_until(next_poll_);
  return inner_->read(buffer, capacity, 0);
}

}  // namespace serial_robot_driver::bench
