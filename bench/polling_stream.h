// A ByteStream that reads its inner stream only once per interval, like a driver that polls its
// port from a timer: what the benchmarks compare the event-driven reader against. Bench-only; no
// robot should run with it.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::bench {

class PollingStream : public transport::ByteStream {
 public:
  /// `interval` in seconds (> 0).
  PollingStream(std::unique_ptr<transport::ByteStream> inner, double interval);

  void open() override;
  void close() override { inner_->close(); }
  bool isOpen() const override { return inner_->isOpen(); }
  /// Sleeps until the next poll instant (ignoring `timeout_ms`), then takes what has arrived.
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  void write(const uint8_t* data, std::size_t size) override { inner_->write(data, size); }
  std::string name() const override { return inner_->name(); }
  transport::StreamInfo info() const override { return inner_->info(); }

 private:
  std::unique_ptr<transport::ByteStream> inner_;
  const std::chrono::steady_clock::duration period_;
  std::chrono::steady_clock::time_point next_poll_;
};

}  // namespace serial_robot_driver::bench
