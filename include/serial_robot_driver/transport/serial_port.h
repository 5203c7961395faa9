// POSIX serial port (termios): raw 8N1 at the configured baud. Reads and writes are independent
// (one reader thread, writers serialized by the caller), as in wjwwood/serial.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/transport/byte_stream.h"
#include "serial_robot_driver/transport/read_waiter.h"

namespace serial_robot_driver::transport {

struct SerialPortOptions {
  std::string path;
  unsigned baud = 115200;
};

/// Threading: one thread may read while another writes (the two share no mutable state besides
/// the fd). open() and close() must not race with a read or write in progress.
class SerialPort : public ByteStream {
 public:
  explicit SerialPort(SerialPortOptions options);
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Opens the port exclusively (an advisory flock plus TIOCEXCL where the driver supports it),
  /// configures it (raw 8N1, no flow control) and drops stale buffered bytes.
  /// Requests ASYNC_LOW_LATENCY where the driver supports it; a pty or a driver that refuses the
  /// ioctl is "not supported", not an error. Reopens when already open.
  /// \throws TransportError kConfigureFailed for an unsupported baud or a path that is no tty,
  ///         kOpenFailed when the path cannot be opened, or "port busy: ... locked by another
  ///         process (pid N, from ...)" when another process holds it (the pid when it can be
  ///         known: a LCK..ttyX lock file or /proc/locks).
  void open() override;
  /// Idempotent; the destructor calls it.
  void close() override;
  bool isOpen() const override { return fd_ >= 0; }
  /// \throws TransportError kDisconnected on hang-up, EOF or EIO (and when not open), kIoError
  ///         for other failures.
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  /// \throws TransportError kDisconnected on EIO/EPIPE/hang-up (and when not open), kIoError when
  ///         the device accepts nothing for ~100 ms or fails otherwise.
  void write(const uint8_t* data, std::size_t size) override;
  std::string name() const override { return options_.path; }

  /// Low latency mode, and the USB-serial adapter's latency_timer in ms (sysfs) when the port is
  /// such an adapter.
  StreamInfo info() const override { return {low_latency_, latency_timer_ms_}; }

  /// A read waits on the port and on a ReadWaiter's eventfd, which ends it at once (stop, or a
  /// writer that saw the port fail), so an idle reader needs no periodic time-out.
  bool wakeable() const override { return waiter_.valid(); }
  void wakeRead() override { waiter_.wake(); }

 private:
  SerialPortOptions options_;
  std::atomic<int> fd_{-1};
  bool low_latency_ = false;
  std::optional<int> latency_timer_ms_;
  ReadWaiter waiter_;
};

/// Who holds a port: a pid and where it was found (a lock file's path, or "/proc/locks").
struct PortHolder {
  long pid;
  std::string source;
};
/// Another live process's lock on `device_path` (UUCP lock file, flock or POSIX lock); nullopt
/// when none can be seen.
std::optional<PortHolder> findPortHolder(const std::string& device_path);

/// The baud rates a port opens at, ascending: the standard Linux rates and the servos' 250000. The
/// one table behind both the parameter check and open().
const std::vector<unsigned>& supportedBaudRates();
bool isSupportedBaud(unsigned baud);
/// supportedBaudRates() as "1200, 2400, ..." for messages.
std::string supportedBaudRatesText();

/// termios speed constant for a baud rate; nullopt when it has none. A supported rate without one
/// (250000) is set by number with termios2 (BOTHER) on Linux.
std::optional<unsigned> baudToSpeed(unsigned baud);

/// The speed an open tty runs at in bits/s (its output speed), read back from the kernel; nullopt
/// when the device refuses to tell.
std::optional<unsigned> readBaudRate(int fd);

/// Reads /sys/bus/usb-serial/devices/<ttyX>/latency_timer for a device path (symlinks resolved).
std::optional<int> readLatencyTimerMs(const std::string& device_path);

/// Shared by SerialPort, TcpStream and sim::PseudoTerminal: waits up to `timeout_ms` for input on
/// the non-blocking `fd` and reads what is there (0 on timeout or EAGAIN/EINTR). Hang-up, EOF, EIO
/// and a socket's reset or time-out (ECONNRESET, ETIMEDOUT, ...) throw TransportError
/// kDisconnected; `what` names the device in error messages. A stream with a `waiter` (watching
/// `fd`) waits there, and its wake-up ends the wait at once with 0; without one, `fd` is polled.
std::size_t readFromFd(int fd, uint8_t* buffer, std::size_t capacity, int timeout_ms,
                       const std::string& what, ReadWaiter* waiter = nullptr);

/// What writeAllToFd() writes to: a socket is written with send(MSG_NOSIGNAL), so a closed peer is
/// an EPIPE error and not a SIGPIPE that would end the process.
enum class FdKind { kTerminal, kSocket };

/// Shared by SerialPort, TcpStream and sim::PseudoTerminal: writes all bytes to the non-blocking
/// `fd`, waiting for room at most `stall_limit` without progress (then kIoError).
/// EIO/EPIPE/ECONNRESET/hang-up → kDisconnected.
void writeAllToFd(int fd, const uint8_t* data, std::size_t size, const std::string& what,
                  std::chrono::milliseconds stall_limit = std::chrono::milliseconds(100),
                  FdKind kind = FdKind::kTerminal);

}  // namespace serial_robot_driver::transport
