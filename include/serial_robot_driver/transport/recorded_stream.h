// A recorded port played back as a ByteStream: the link reads recorded chunks, one per read(), at
// their recorded pace (or as fast as it can), and each read reports the chunk's recorded arrival
// time. What the driver writes goes nowhere and is counted. The replay is thus "another port"
// behind SerialLink: the framers, the devices and the publishers run unchanged.
//
// Threading model: a port's chunks are read by that port's reader thread only (the link opens a
// new RecordedStream on the same RecordedPort after each recorded reopen); writes come from any
// thread and only touch atomic counters; finished() and stats() may be called from anywhere.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::transport {

using SteadyTime = std::chrono::steady_clock::time_point;

struct RecordedChunk {
  SteadyTime arrival;         ///< when it was read, as the link hands it on to the frames
  std::vector<uint8_t> data;  ///< empty: the port was (re)opened here
};

/// When recorded chunks are due: `rate` times the recorded pace from the moment it is built (or
/// restarted), the earliest recorded arrival being due at once. Rate 0: everything is due at once.
class ReplayPacing {
 public:
  ReplayPacing(double rate, SteadyTime first_arrival);
  SteadyTime dueAt(SteadyTime arrival) const;
  bool paced() const { return rate_ > 0; }
  /// The replay begins now. Call before the readers start (it is not synchronized with dueAt).
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  double rate_;
  SteadyTime first_arrival_;
  SteadyTime start_;
};

struct RecordedPortStats {
  uint64_t chunks_fed = 0;
  uint64_t bytes_fed = 0;
  uint64_t reopens = 0;           ///< recorded (re)opens of the port, the first one included
  uint64_t writes_discarded = 0;  ///< what the driver wrote: it goes nowhere
  uint64_t bytes_discarded = 0;
};

/// One port's recording and how far the replay got.
class RecordedPort {
 public:
  RecordedPort(std::string name, std::vector<RecordedChunk> chunks,
               std::shared_ptr<const ReplayPacing> pacing);

  const std::string& name() const { return name_; }
  /// Every chunk has been handed out (and the read after the last one has begun).
  bool finished() const { return finished_.load(); }
  RecordedPortStats stats() const;

 private:
  friend class RecordedStream;
  std::string name_;
  std::vector<RecordedChunk> chunks_;
  std::shared_ptr<const ReplayPacing> pacing_;
  std::size_t next_ = 0;    // reader thread only
  std::size_t offset_ = 0;  // into chunks_[next_], when a chunk exceeds a read's capacity
  std::atomic<bool> finished_{false};
  std::atomic<uint64_t> chunks_fed_{0}, bytes_fed_{0}, reopens_{0};
  std::atomic<uint64_t> writes_discarded_{0}, bytes_discarded_{0};
};

class RecordedStream : public ByteStream {
 public:
  explicit RecordedStream(std::shared_ptr<RecordedPort> port) : port_(std::move(port)) {}

  /// Takes the recorded "port opened" mark, when it is next.
  void open() override;
  void close() override { open_ = false; }
  bool isOpen() const override { return open_; }
  /// The next chunk once it is due (0 while none is due within `timeout_ms`, and forever after
  /// the last one). Throws TransportError(kDisconnected) where the recording reopened the port.
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  /// Counts and drops the bytes.
  void write(const uint8_t* data, std::size_t size) override;
  std::string name() const override { return port_->name(); }
  std::optional<SteadyTime> arrivalTime() const override { return arrival_; }

 private:
  std::shared_ptr<RecordedPort> port_;
  bool open_ = false;
  std::optional<SteadyTime> arrival_;
};

}  // namespace serial_robot_driver::transport
