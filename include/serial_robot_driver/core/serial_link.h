// One serial port shared by the devices that name its path: the port, its framer, its reader thread
// and its reconnect loop.
//
// Threading model of a link:
//  - ONE reader thread per port owns every read. It opens the port (retrying every
//    reconnect_interval while the device node is missing), feeds the bytes to the port's
//    StreamFramer and hands each verified frame to the listeners, stamped with the time the chunk
//    holding its last byte was read. Listeners run on this thread: they decode, publish and return;
//    they never wait on the wire.
//  - Any thread may write(): writes are serialized by a per-port mutex and never wait for an
//  answer.
//    A failed write marks the port lost; the reader thread then closes and reopens it.
//  - Only the reader thread opens and closes the stream, so a read never races a close.
//  - A ChunkObserver (wire capture), when set, sees every chunk on the thread that moved it: reads
//    on the reader thread, writes on the writer's thread INSIDE the per-port write lock, so the
//    capture has the writes in the order they went on the wire. It must copy what it keeps and
//    return at once (it holds up every writer of the port); without one, the only cost is a null
//    check per read and per write.
//  - With options.realtime_priority the reader thread runs SCHED_FIFO (core/realtime.h), or at the
//    normal policy where the process may not.
//  - The wire is an input like any topic: an exception that a listener or the worker lets out is
//    caught on the reader thread, counted (LinkStats::handler_errors), logged (throttled) and its
//    frame or event dropped for that listener. It never ends the thread, nor with it the process.
//  - An idle reader sleeps in its read until data comes; stop(), wake() and a writer that saw the
//    port fail wake it through the stream (ByteStream::wakeRead), not by a periodic time-out.
//  - A LinkWorker (setWorker: the servo bus, a request/response device) runs ON the reader thread,
//    between reads, whenever its nextWork() falls due: it writes a request and waits for the
//    answer by pump()ing the port itself, so an answer reaches the thread that waits for it
//    without a second thread being woken. pump() hands every frame to every listener as the
//    reader's own loop does, so the other devices of a shared port are served meanwhile. Other
//    threads reach the worker through wake().
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/clock.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::core {

/// How every device puts a frame on its port: writes one whole frame and returns false when the
/// port is down or the write failed (SerialLink::write). Tests pass a fake.
using FrameWriter = std::function<bool(const std::vector<uint8_t>&)>;

/// Implemented by the devices on a port. All calls come from the link's reader thread, the last
/// onLinkDown too (the reader closes the port on its way out of stop()).
class LinkListener {
 public:
  virtual ~LinkListener() = default;
  /// The port was (re)opened: e.g. the base must send a Reset before its next speed frame.
  virtual void onLinkUp() {}
  virtual void onLinkDown() {}
  /// An attempt to open the port failed (it is retried every reconnect_interval).
  virtual void onOpenFailed(const std::string& /*error*/) {}
  /// A verified frame of one of the families the port's framer accepts.
  virtual void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                       Clock::time_point arrival) = 0;
};

/// Work that runs on a link's reader thread (see the threading model above).
class LinkWorker {
 public:
  virtual ~LinkWorker() = default;
  /// When work() has something to do next; Clock::time_point::max(): nothing until woken.
  /// Called before every read, so it must be cheap.
  virtual Clock::time_point nextWork() = 0;
  /// Does one piece of the work due. It may write and pump() the link for an answer, for a
  /// bounded time; it must not wait for other threads.
  virtual void work() = 0;
};

/// One chunk as it crossed the port: what one read() returned, or one whole write().
struct WireChunk {
  const std::string& port;  ///< the link's path
  bool outbound;            ///< written by the driver (true) or read from the device (false)
  /// The bytes; size 0 (inbound) marks the port being (re)opened, so a replay restarts its framer
  /// where the live link did.
  const uint8_t* data;
  std::size_t size;
  Clock::time_point time;  ///< when it was read (the frames' arrival stamp) or written
};

/// Sees every chunk of a link (see the threading model above).
class ChunkObserver {
 public:
  virtual ~ChunkObserver() = default;
  virtual void onChunk(const WireChunk& chunk) = 0;
};

struct SerialLinkOptions {
  std::string path;
  unsigned baud = 115200;
  double reconnect_interval = 1.0;  ///< s between attempts to reopen a lost port
  protocol::FramerConfig framer;
  /// An incomplete frame with no new byte for this long is given up on, so the frames behind a
  /// stray header are not held back (the servo bus uses its answer timeout). 0: never.
  std::chrono::milliseconds stale_frame_timeout{0};
  /// The reader thread's SCHED_FIFO priority (core/realtime.h: ~realtime_priority); 0: normal.
  int realtime_priority = 0;
  /// The reader thread's fair-scheduler slice (core/scheduler_slice.h); 0: the kernel's.
  int scheduler_slice_us = 0;
};

struct LinkStats {
  bool connected = false;
  uint64_t connects = 0;  ///< successful opens (the first one included)
  uint64_t disconnects = 0;
  uint64_t frames_out = 0;
  uint64_t bytes_out = 0;
  uint64_t write_failures = 0;  ///< writes refused because the port was down, or that failed
  protocol::FramerStats framer;
  bool low_latency = false;
  std::optional<int> latency_timer_ms;  ///< USB adapter's latency_timer, when known
  std::string last_error;               ///< why the port was last lost or could not be opened
  /// Exceptions a listener or the worker let out on the reader thread: each is caught there, its
  /// frame or event dropped for that listener, and the reader goes on.
  uint64_t handler_errors = 0;
  std::string last_handler_error;  ///< "<where>: <what>" of the last one
};

class SerialLink {
 public:
  using StreamFactory =
      std::function<std::unique_ptr<transport::ByteStream>(const SerialLinkOptions&)>;

  /// `factory` builds the stream to open; the default is a termios SerialPort. Benchmarks plug in
  /// other streams here (e.g. one that polls), so the link itself has one way of reading.
  explicit SerialLink(SerialLinkOptions options, StreamFactory factory = {});
  ~SerialLink();
  SerialLink(const SerialLink&) = delete;
  SerialLink& operator=(const SerialLink&) = delete;

  /// Listeners must be added before start() and outlive the link's thread.
  void addListener(LinkListener* listener);
  /// At most one; set before start(), it must outlive the link's threads. nullptr: none.
  void setChunkObserver(ChunkObserver* observer) { observer_ = observer; }
  /// At most one; set before start(), it must outlive the reader thread (stop() the link first).
  void setWorker(LinkWorker* worker) { worker_ = worker; }
  void start();
  /// Stops the reader thread and closes the port. Idempotent.
  void stop();

  /// Writes one whole frame. Returns false (and counts it) when the port is down or the write
  /// failed; a failed write also schedules a reconnect.
  bool write(const std::vector<uint8_t>& frame);
  bool write(const uint8_t* data, std::size_t size);
  /// A FrameWriter that writes to this link (which must outlive it).
  FrameWriter writer();

  bool connected() const { return connected_.load(); }
  LinkStats stats() const;
  const SerialLinkOptions& options() const { return options_; }

  /// Blocks until the link is connected or `timeout` elapses (start-up helpers and tests).
  bool waitConnected(std::chrono::milliseconds timeout) const;

  /// Reader thread only (inside LinkWorker::work): reads once, waiting until `until` at most, and
  /// hands the frames to the listeners. False when the port is down, lost or stopping.
  bool pump(Clock::time_point until);
  /// Whether the caller is the reader thread (the one that may pump()).
  bool onReaderThread() const;
  /// Any thread: the reader asks the worker's nextWork() again at once.
  void wake();

 private:
  void readerLoop();
  /// One read (up to `until`, the stale-frame and the stream's own limits) and its frames.
  void readOnce(Clock::time_point until);
  /// A partial frame is buffered and the port gives such frames up after a stale-frame timeout.
  bool timesPartialFrame() const;
  /// Drops the framer's candidates that a stale-frame timeout of silence left incomplete.
  void dropStaleCandidates();
  bool tryOpen();
  void closeStream(const std::string& reason);
  /// Waits while the port is down: until `until`, stop() or wake().
  void waitForRetry(Clock::time_point until);
  Clock::duration reconnectInterval() const;
  void wakeReader();  // a read in progress returns at once (stop, loss seen by a writer)
  /// `event(listener)` for every listener, each guarded (the reader thread's last line).
  template <typename Event>
  void toListeners(const char* what, const Event& event);
  /// Counts and logs (throttled) an exception caught on the reader thread.
  void noteHandlerError(const char* where, const std::string& what);

  SerialLinkOptions options_;
  StreamFactory factory_;
  std::vector<LinkListener*> listeners_;
  ChunkObserver* observer_ = nullptr;
  LinkWorker* worker_ = nullptr;
  protocol::StreamFramer framer_;
  Clock::time_point chunk_arrival_;
  std::array<uint8_t, 4096> chunk_{};      // reader thread only: what one read returns
  Clock::time_point next_open_attempt_{};  // reader thread only

  std::unique_ptr<transport::ByteStream> stream_;  // opened/closed by the reader thread only
  mutable std::mutex write_mutex_;                 // serializes writes and guards stream_ swaps
  std::atomic<bool> connected_{false};
  std::atomic<bool> lost_{false};  // a writer saw the port fail
  std::atomic<bool> stopping_{false};
  mutable std::mutex state_mutex_;  // guards stats_ and the stop condition
  mutable std::condition_variable state_cv_;
  bool wake_pending_ = false;  // guarded by state_mutex_: wake() came
  LinkStats stats_;
  LogThrottle handler_error_log_{5.0};
  std::thread reader_;
};

}  // namespace serial_robot_driver::core
