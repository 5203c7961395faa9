// A SerialLink's stream in memory, for device tests without a port: what the driver writes is
// kept, what the test feeds is read. Shared by the test and the link's reader thread.
#pragma once

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/transport/byte_stream.h"

namespace test_support {

/// The bytes both ways; outlives the streams the link opens on it.
class MemoryWire {
 public:
  /// The device sends `bytes` (read by the link's next read).
  void feed(const std::vector<uint8_t>& bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    inbound_.insert(inbound_.end(), bytes.begin(), bytes.end());
    changed_.notify_all();
  }
  /// Every byte the driver wrote so far.
  std::vector<uint8_t> written() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return written_;
  }

  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, std::chrono::milliseconds(timeout_ms),
                      [this] { return !inbound_.empty(); });
    const std::size_t size = std::min(capacity, inbound_.size());
    std::copy_n(inbound_.begin(), size, buffer);
    inbound_.erase(inbound_.begin(), inbound_.begin() + static_cast<std::ptrdiff_t>(size));
    return size;
  }
  void write(const uint8_t* data, std::size_t size) {
    std::lock_guard<std::mutex> lock(mutex_);
    written_.insert(written_.end(), data, data + size);
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<uint8_t> inbound_;
  std::vector<uint8_t> written_;
};

class MemoryStream : public serial_robot_driver::transport::ByteStream {
 public:
  explicit MemoryStream(MemoryWire& wire) : wire_(wire) {}
  void open() override { open_ = true; }
  void close() override { open_ = false; }
  bool isOpen() const override { return open_; }
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override {
    // Short waits: the link notices a stop request between them.
    return wire_.read(buffer, capacity, std::min(timeout_ms, 10));
  }
  void write(const uint8_t* data, std::size_t size) override { wire_.write(data, size); }
  std::string name() const override { return "memory"; }

 private:
  MemoryWire& wire_;
  bool open_ = false;
};

/// A SerialLink::StreamFactory whose streams are `wire`.
inline serial_robot_driver::core::SerialLink::StreamFactory memoryStreams(MemoryWire& wire) {
  return [&wire](const serial_robot_driver::core::SerialLinkOptions&) {
    return std::make_unique<MemoryStream>(wire);
  };
}

}  // namespace test_support
