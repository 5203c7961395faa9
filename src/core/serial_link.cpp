#include "serial_robot_driver/core/serial_link.h"

#include <pthread.h>

#include <algorithm>
#include <optional>

#include "serial_robot_driver/core/guarded_call.h"
#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/transport/serial_port.h"
#include "serial_robot_driver/transport/tcp_stream.h"

namespace serial_robot_driver::core {

namespace {
/// How long one read waits before the reader thread checks for stop/lost flags. Data wakes it at
/// once, so this only bounds how fast stop() returns and a writer-detected loss is acted on, for
/// streams that cannot be woken. A wakeable stream is woken for those, so its reader sleeps until
/// data comes: an idle port costs no periodic wake-ups (each costs tens of microseconds here), and
/// with nothing due it waits without a timer at all (kNoTimeout), which would otherwise be armed
/// and cancelled around every frame for nothing.
constexpr int kReadTimeoutMs = 100;
/// The longest a wakeable stream's read waits for something due (a worker's transaction, a stale
/// partial frame): keeps far deadlines within an int of milliseconds.
constexpr int kWakeableReadTimeoutMs = 5000;
constexpr int kNoTimeout = -1;
/// The longest a reader with nothing to do waits for its port to be reopened in one go.
constexpr int kLongestIdleWaitS = 3600;

/// The one place a port path becomes a stream: a device path is a serial port, a tcp:// URL a
/// connection to a network serial server (whose own line settings make the baud meaningless here).
std::unique_ptr<transport::ByteStream> openSerialPort(const SerialLinkOptions& options) {
  if (transport::isTcpUrl(options.path)) {
    return std::make_unique<transport::TcpStream>(options.path);
  }
  return std::make_unique<transport::SerialPort>(
      transport::SerialPortOptions{options.path, options.baud});
}

}  // namespace

template <typename Event>
void SerialLink::toListeners(const char* what, const Event& event) {
  for (LinkListener* listener : listeners_) {
    catchAll([&] { event(*listener); },
             [&](const std::string& error) { noteHandlerError(what, error); });
  }
}

SerialLink::SerialLink(SerialLinkOptions options, StreamFactory factory)
    : options_(std::move(options)),
      factory_(factory ? std::move(factory) : StreamFactory(openSerialPort)),
      framer_(options_.framer,
              [this](protocol::FrameFamily family, const uint8_t* data, std::size_t size) {
                toListeners("a frame's listener", [&](LinkListener& listener) {
                  listener.onFrame(family, data, size, chunk_arrival_);
                });
              }) {}

void SerialLink::noteHandlerError(const char* where, const std::string& what) {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.handler_errors;
    stats_.last_handler_error = std::string(where) + ": " + what;
  }
  if (handler_error_log_.pass()) {
    log(LogLevel::kError, "%s: internal error on the reader thread, dropped: %s (%s)",
        options_.path.c_str(), what.c_str(), where);
  }
}

SerialLink::~SerialLink() { stop(); }

void SerialLink::addListener(LinkListener* listener) { listeners_.push_back(listener); }

void SerialLink::start() {
  if (reader_.joinable()) return;
  stopping_ = false;
  reader_ = std::thread([this] { readerLoop(); });
}

void SerialLink::stop() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    stopping_ = true;
  }
  state_cv_.notify_all();
  wakeReader();
  // The reader closes the port on its way out, so onLinkDown stays on the reader thread.
  if (reader_.joinable()) reader_.join();
}

bool SerialLink::write(const std::vector<uint8_t>& frame) {
  return write(frame.data(), frame.size());
}

FrameWriter SerialLink::writer() {
  return [this](const std::vector<uint8_t>& frame) { return write(frame); };
}

bool SerialLink::write(const uint8_t* data, std::size_t size) {
  std::string error;
  {
    std::lock_guard<std::mutex> lock(write_mutex_);
    if (!connected_ || lost_ || !stream_) {
      error = "port is not connected";
    } else {
      try {
        stream_->write(data, size);
        if (observer_) observer_->onChunk({options_.path, true, data, size, Clock::now()});
      } catch (const transport::TransportError& e) {
        error = e.what();
        lost_ = true;  // the reader thread closes and reopens the port
        stream_->wakeRead();
      }
    }
  }
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (!error.empty()) {
    ++stats_.write_failures;
    if (lost_) stats_.last_error = error;
    return false;
  }
  ++stats_.frames_out;
  stats_.bytes_out += size;
  return true;
}

LinkStats SerialLink::stats() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  LinkStats copy = stats_;
  copy.connected = connected_;
  return copy;
}

bool SerialLink::waitConnected(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(state_mutex_);
  return state_cv_.wait_for(lock, timeout, [this] {
    return connected_.load() || stopping_.load();
  }) && connected_;
}

bool SerialLink::tryOpen() {
  std::unique_ptr<transport::ByteStream> stream;
  std::string error;
  try {
    stream = factory_(options_);
    stream->open();
  } catch (const transport::TransportError& e) {
    error = e.what();
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (!error.empty()) {
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      stats_.last_error = error;
    }
    toListeners("a listener of a failed open",
                [&](LinkListener& listener) { listener.onOpenFailed(error); });
    return false;
  }
  framer_.reset();  // a partial frame from before the loss means nothing now
  const transport::StreamInfo info = stream->info();
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.connects;
    stats_.low_latency = info.low_latency;
    stats_.latency_timer_ms = info.latency_timer_ms;
  }
  if (observer_) observer_->onChunk({options_.path, false, nullptr, 0, Clock::now()});
  // Listeners hear "up" before any write can succeed: the base must have queued its Reset first.
  toListeners("a listener of the link coming up",
              [](LinkListener& listener) { listener.onLinkUp(); });
  {
    std::lock_guard<std::mutex> lock(write_mutex_);
    stream_ = std::move(stream);
    lost_ = false;
    connected_ = true;
  }
  { std::lock_guard<std::mutex> lock(state_mutex_); }  // no lost wake-up for waitConnected()
  state_cv_.notify_all();
  return true;
}

void SerialLink::closeStream(const std::string& reason) {
  bool was_connected = false;
  {
    std::lock_guard<std::mutex> lock(write_mutex_);
    was_connected = connected_;
    connected_ = false;
    if (stream_) stream_->close();
    stream_.reset();
  }
  if (!was_connected) return;
  next_open_attempt_ = Clock::now() + reconnectInterval();  // a lost port is reopened after a pause
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.disconnects;
    stats_.last_error = reason;
  }
  toListeners("a listener of the link going down",
              [](LinkListener& listener) { listener.onLinkDown(); });
}

void SerialLink::wakeReader() {
  std::lock_guard<std::mutex> lock(write_mutex_);  // stream_ is swapped under it
  if (stream_) stream_->wakeRead();
}

void SerialLink::wake() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    wake_pending_ = true;
  }
  state_cv_.notify_all();  // a reader waiting to reopen the port
  wakeReader();            // a reader in read()
}

bool SerialLink::onReaderThread() const { return std::this_thread::get_id() == reader_.get_id(); }

void SerialLink::waitForRetry(Clock::time_point until) {
  // Bounded: a far deadline (nothing to do) must not overflow the condition variable's clock.
  until = std::min(until, Clock::now() + std::chrono::seconds(kLongestIdleWaitS));
  std::unique_lock<std::mutex> lock(state_mutex_);
  state_cv_.wait_until(lock, until, [this] { return stopping_.load() || wake_pending_; });
  wake_pending_ = false;
}

void SerialLink::readerLoop() {
  ::pthread_setname_np(::pthread_self(), "srd_reader");  // as ps -L, top -H and perf show it
  // The slice first: a thread already at SCHED_FIFO takes none. Either refused, it reads all the
  // same at the normal policy.
  requestSchedulerSlice(options_.scheduler_slice_us);
  enterRealtime(options_.realtime_priority);
  while (!stopping_) {
    const Clock::time_point work_due =
        worker_ != nullptr ? worker_->nextWork() : Clock::time_point::max();
    if (work_due <= Clock::now()) {
      catchAll([this] { worker_->work(); },
               [this](const std::string& error) { noteHandlerError("the port's worker", error); });
      continue;
    }
    if (!connected_) {
      if (Clock::now() >= next_open_attempt_ && !tryOpen()) {
        next_open_attempt_ = Clock::now() + reconnectInterval();
      }
      if (!connected_) waitForRetry(std::min(next_open_attempt_, work_due));
      continue;
    }
    if (lost_) {
      std::string reason;
      {
        std::lock_guard<std::mutex> lock(state_mutex_);
        reason = stats_.last_error;
      }
      closeStream(reason);
      continue;
    }
    readOnce(work_due);
  }
  if (stream_) closeStream("stopped");
}

bool SerialLink::pump(Clock::time_point until) {
  if (stopping_ || !connected_ || lost_) return false;
  readOnce(until);
  return connected_ && !lost_ && !stopping_;
}

bool SerialLink::timesPartialFrame() const {
  return options_.stale_frame_timeout.count() > 0 && framer_.buffered() > 0;
}

void SerialLink::dropStaleCandidates() {
  // No byte for a whole timeout: what is buffered will not complete. Frames found behind the stale
  // candidate keep the arrival time of their bytes.
  while (framer_.dropStaleCandidate()) {
  }
  std::lock_guard<std::mutex> lock(state_mutex_);
  stats_.framer = framer_.stats();
}

Clock::duration SerialLink::reconnectInterval() const {
  return fromSeconds(options_.reconnect_interval);
}

void SerialLink::readOnce(Clock::time_point until) {
  // A wakeable stream sleeps until data, stop(), wake() or a failed write wakes it, or something
  // falls due; the others poll.
  std::optional<std::chrono::milliseconds> read_timeout;
  if (!stream_->wakeable()) read_timeout = std::chrono::milliseconds(kReadTimeoutMs);
  if (until != Clock::time_point::max()) {
    // Whole milliseconds, rounded up: the wait cannot be shorter, and rounding down would spin.
    const auto due =
        std::clamp(std::chrono::ceil<std::chrono::milliseconds>(until - Clock::now()),
                   std::chrono::milliseconds(0), std::chrono::milliseconds(kWakeableReadTimeoutMs));
    read_timeout = std::min(read_timeout.value_or(due), due);
  }
  if (timesPartialFrame()) {
    // The stream's clock: a replay measures the recorded silence on its own timeline.
    const auto quiet = stream_->now() - chunk_arrival_;
    if (quiet >= options_.stale_frame_timeout) {
      dropStaleCandidates();
      return;
    }
    // Limited as a duration first: the int conversion never sees more than kWakeableReadTimeoutMs.
    const auto left = std::clamp(
        std::chrono::ceil<std::chrono::milliseconds>(options_.stale_frame_timeout - quiet),
        std::chrono::milliseconds(1), std::chrono::milliseconds(kWakeableReadTimeoutMs));
    read_timeout = std::min(read_timeout.value_or(left), left);
  }
  const int timeout_ms = read_timeout ? static_cast<int>(read_timeout->count()) : kNoTimeout;
  std::size_t n = 0;
  try {
    n = stream_->read(chunk_.data(), chunk_.size(), timeout_ms);
  } catch (const transport::TransportError& e) {
    closeStream(e.what());
    return;
  }
  if (n == 0) return;
  // A replayed recording knows when its bytes arrived; a live port's bytes arrived now.
  const Clock::time_point arrival = stream_->arrivalTime().value_or(Clock::now());
  // Bytes read a whole timeout after the last ones find the buffered candidate stale even when a
  // busy machine, not the line, kept them: judged by the arrival times the capture records, a
  // replay drops exactly what the live run dropped.
  if (timesPartialFrame() && arrival - chunk_arrival_ >= options_.stale_frame_timeout) {
    dropStaleCandidates();
  }
  chunk_arrival_ = arrival;
  if (observer_) observer_->onChunk({options_.path, false, chunk_.data(), n, chunk_arrival_});
  framer_.feed(chunk_.data(), n);
  std::lock_guard<std::mutex> lock(state_mutex_);
  stats_.framer = framer_.stats();
}

}  // namespace serial_robot_driver::core
