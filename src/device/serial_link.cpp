#include "serial_robot_driver/device/serial_link.h"

#include <algorithm>
#include <array>

#include "serial_robot_driver/transport/serial_port.h"

namespace serial_robot_driver::device {

namespace {
/// How long one read waits before the reader thread checks for stop/lost flags. Data wakes it at
/// once, so this only bounds how fast stop() returns and a writer-detected loss is acted on, for
/// streams that cannot be woken. A wakeable stream is woken for those, so its reader sleeps until
/// data comes: an idle port costs no periodic wake-ups (each costs tens of microseconds here).
constexpr int kReadTimeoutMs = 100;
constexpr int kWakeableReadTimeoutMs = 5000;
constexpr std::size_t kReadChunk = 4096;

std::unique_ptr<transport::ByteStream> openSerialPort(const SerialLinkOptions& options) {
  return std::make_unique<transport::SerialPort>(transport::SerialPortOptions{options.path, options.baud});
}
}  // namespace

SerialLink::SerialLink(SerialLinkOptions options, StreamFactory factory)
    : options_(std::move(options)),
      factory_(factory ? std::move(factory) : StreamFactory(openSerialPort)),
      framer_(options_.framer,
              [this](protocol::FrameFamily family, const uint8_t* data, std::size_t size) {
                for (LinkListener* listener : listeners_) {
                  listener->onFrame(family, data, size, chunk_arrival_);
                }
              }) {}

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

bool SerialLink::write(const std::vector<uint8_t>& frame) { return write(frame.data(), frame.size()); }

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
  return state_cv_.wait_for(lock, timeout, [this] { return connected_.load() || stopping_.load(); }) &&
         connected_;
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
    for (LinkListener* listener : listeners_) listener->onOpenFailed(error);
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
  for (LinkListener* listener : listeners_) listener->onLinkUp();
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
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.disconnects;
    stats_.last_error = reason;
  }
  for (LinkListener* listener : listeners_) listener->onLinkDown();
}

void SerialLink::wakeReader() {
  std::lock_guard<std::mutex> lock(write_mutex_);  // stream_ is swapped under it
  if (stream_) stream_->wakeRead();
}

void SerialLink::sleepBeforeRetry() {
  std::unique_lock<std::mutex> lock(state_mutex_);
  state_cv_.wait_for(lock, std::chrono::duration<double>(options_.reconnect_interval),
                     [this] { return stopping_.load(); });
}

void SerialLink::readerLoop() {
  std::array<uint8_t, kReadChunk> chunk{};
  while (!stopping_) {
    if (!connected_) {
      if (!tryOpen()) sleepBeforeRetry();
      continue;
    }
    if (lost_) {
      std::string reason;
      {
        std::lock_guard<std::mutex> lock(state_mutex_);
        reason = stats_.last_error;
      }
      closeStream(reason);
      sleepBeforeRetry();
      continue;
    }
    // A wakeable stream sleeps until data, stop() or a failed write wakes it; the others poll.
    const int longest_read_ms = stream_->wakeable() ? kWakeableReadTimeoutMs : kReadTimeoutMs;
    int read_timeout_ms = longest_read_ms;
    if (options_.stale_frame_timeout.count() > 0 && framer_.buffered() > 0) {
      // The stream's clock: a replay measures the recorded silence on its own timeline.
      const auto quiet = stream_->now() - chunk_arrival_;
      if (quiet >= options_.stale_frame_timeout) {
        // No byte for a whole timeout: what is buffered will not complete. Frames found behind
        // the stale candidate keep the arrival time of their bytes.
        while (framer_.dropStaleCandidate()) {
        }
        std::lock_guard<std::mutex> lock(state_mutex_);
        stats_.framer = framer_.stats();
        continue;
      }
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(
          options_.stale_frame_timeout - quiet);
      // Clamped as a duration first: the int conversion never sees more than longest_read_ms.
      read_timeout_ms = static_cast<int>(
          std::clamp(left, std::chrono::milliseconds(1), std::chrono::milliseconds(longest_read_ms))
              .count());
    }
    std::size_t n = 0;
    try {
      n = stream_->read(chunk.data(), chunk.size(), read_timeout_ms);
    } catch (const transport::TransportError& e) {
      closeStream(e.what());
      sleepBeforeRetry();
      continue;
    }
    if (n == 0) continue;
    // A replayed recording knows when its bytes arrived; a live port's bytes arrived now.
    chunk_arrival_ = stream_->arrivalTime().value_or(Clock::now());
    if (observer_) observer_->onChunk({options_.path, false, chunk.data(), n, chunk_arrival_});
    framer_.feed(chunk.data(), n);
    std::lock_guard<std::mutex> lock(state_mutex_);
    stats_.framer = framer_.stats();
  }
  if (stream_) closeStream("stopped");
}

}  // namespace serial_robot_driver::device
