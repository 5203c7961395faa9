// A recorded port played back as a ByteStream: the link reads recorded chunks, one per read(), at
// their recorded pace (or as fast as it can), and each read reports the chunk's recorded arrival
// time. What the driver writes goes nowhere and is counted. The replay is thus "another port"
// behind SerialLink: the framers, the devices and the publishers run unchanged.
//
// Threading model: a port's chunks are read by that port's reader thread only (the link opens a
// new RecordedStream on the same RecordedPort after each recorded reopen), and now() is asked on
// that thread too; writes come from any
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
/// A recorded stamp: nanoseconds since the Unix epoch (a ROS wall-clock stamp).
using RecordedStamp = std::chrono::nanoseconds;

struct RecordedChunk {
  RecordedStamp recorded;     ///< when it was read on the recorded run
  std::vector<uint8_t> data;  ///< empty: the port was (re)opened here
};

/// The replay's own timeline. Recorded stamps are wall-clock times; the link's timers (the stale
/// partial frame) run on the steady clock. Each recorded stamp therefore gets a steady time point:
/// the replay's start plus its offset from the first recorded chunk, so recorded gaps keep their
/// length in the link's terms at any rate, and stamps map back exactly.
/// Rate r > 0: the timeline runs r times as fast as the steady clock from the start (rate 1: it
/// is the steady clock), and a chunk is due when the timeline reaches it. Rate 0: nothing waits;
/// each port's clock jumps to its next chunk (RecordedStream::now()).
class ReplayPacing {
 public:
  /// `first`: the earliest recorded chunk; `end`: the end of the recording (its latest stamp, of
  /// any topic), until which the replay keeps running so that a silence at the end counts too.
  ReplayPacing(double rate, RecordedStamp first, RecordedStamp end);
  bool paced() const { return rate_ > 0; }
  double rate() const { return rate_; }
  /// The replay begins now. Call before the readers start (it is not synchronized with readers).
  void restart() { start_ = std::chrono::steady_clock::now(); }

  /// Where a recorded stamp lies on the timeline, and back (exact: whole nanoseconds).
  SteadyTime onTimeline(RecordedStamp recorded) const { return start_ + (recorded - first_); }
  RecordedStamp recordedAt(SteadyTime on_timeline) const { return first_ + (on_timeline - start_); }
  SteadyTime end() const { return onTimeline(end_); }
  /// The timeline's present (paced replays; a rate-0 port keeps a clock of its own).
  SteadyTime now() const;
  /// How long to wait on the steady clock for `span` of the timeline to pass (paced replays).
  std::chrono::nanoseconds steadyWait(std::chrono::nanoseconds span) const;

 private:
  double rate_;
  RecordedStamp first_;
  RecordedStamp end_;
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
  /// The next chunk once it is due (0 while none is due within `timeout_ms` of the timeline, and
  /// forever after the last one). Throws TransportError(kDisconnected) where the recording
  /// reopened the port. The port is finished once the timeline has reached the recording's end.
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  /// Counts and drops the bytes.
  void write(const uint8_t* data, std::size_t size) override;
  std::string name() const override { return port_->name(); }
  /// The chunk's recorded stamp on the replay's timeline.
  std::optional<SteadyTime> arrivalTime() const override { return arrival_; }
  /// The timeline's present, never past the next chunk not yet read; at rate 0, the next chunk's
  /// time (or the end), as if the recorded silence before it had passed (before a recorded
  /// reopen: the last chunk's time).
  SteadyTime now() const override;

 private:
  std::shared_ptr<RecordedPort> port_;
  bool open_ = false;
  std::optional<SteadyTime> arrival_;
};

}  // namespace serial_robot_driver::transport
