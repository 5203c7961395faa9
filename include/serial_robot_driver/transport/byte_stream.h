// The transport seen by the rest of the driver: a byte stream that can be opened, read with a
// timeout, written and closed. SerialPort implements it with termios; tests use a pseudo-terminal
// or an in-memory fake.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace serial_robot_driver::transport {

/// Why a transport operation failed. kDisconnected covers EOF, EIO (a pty whose other end closed,
/// an unplugged USB adapter) and a device node that disappeared.
enum class TransportErrorKind { kOpenFailed, kConfigureFailed, kDisconnected, kIoError };

class TransportError : public std::runtime_error {
 public:
  TransportError(TransportErrorKind kind, const std::string& what)
      : std::runtime_error(what), kind_(kind) {}
  TransportErrorKind kind() const { return kind_; }

 private:
  TransportErrorKind kind_;
};

/// What a stream tells about itself once open (diagnostics and the latency hint).
struct StreamInfo {
  bool low_latency = false;             ///< the driver honours ASYNC_LOW_LATENCY
  std::optional<int> latency_timer_ms;  ///< USB-serial adapter's latency_timer, when known
};

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  virtual void open() = 0;
  virtual void close() = 0;
  virtual bool isOpen() const = 0;
  /// Waits up to `timeout_ms` for data and returns what arrived (0 on timeout: not an error). A
  /// wakeable() stream also takes -1: until data comes or wakeRead() is called.
  /// Throws TransportError when the device is gone.
  virtual std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) = 0;
  /// Writes all bytes or throws TransportError.
  virtual void write(const uint8_t* data, std::size_t size) = 0;
  virtual std::string name() const = 0;
  /// Valid after open(); a stream that is no serial port has nothing to tell.
  virtual StreamInfo info() const { return {}; }
  /// When the bytes of the last read() arrived, for a stream that knows it better than the
  /// reader's clock (a replayed recording); nothing: they arrived when read() returned.
  virtual std::optional<std::chrono::steady_clock::time_point> arrivalTime() const { return {}; }
  /// The clock arrivalTime() and the reader's timers (the stale partial frame) run on: the steady
  /// clock, or a replay's own timeline.
  virtual std::chrono::steady_clock::time_point now() const {
    return std::chrono::steady_clock::now();
  }
  /// Whether wakeRead() works. A reader of a stream that cannot be woken must use short read
  /// timeouts to notice a stop request; one that can sleeps until data or a wake-up comes.
  virtual bool wakeable() const { return false; }
  /// Makes a read() in progress in another thread (or the next one) return 0 at once. Thread-safe
  /// with read(); a no-op for streams that are not wakeable().
  virtual void wakeRead() {}
};

}  // namespace serial_robot_driver::transport
