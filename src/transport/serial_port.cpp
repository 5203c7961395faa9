#include "serial_robot_driver/transport/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include "serial_robot_driver/transport/termios2_baud.h"

#ifdef __linux__
#include <linux/serial.h>
#endif

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <utility>

namespace serial_robot_driver::transport {
namespace {

std::string errnoText(int error_number) { return std::strerror(error_number); }

bool isDisconnectErrno(int error_number) {
  // EIO: pty whose master closed / USB adapter gone; ENXIO, ENODEV: device node vanished. The
  // socket errors (a tty never reports them): the peer reset or closed the connection, or
  // keepalive / TCP_USER_TIMEOUT gave up on a peer that went silent (a pulled cable).
  return error_number == EIO || error_number == EPIPE || error_number == ENXIO ||
         error_number == ENODEV || error_number == EBADF || error_number == ECONNRESET ||
         error_number == ECONNABORTED || error_number == ETIMEDOUT || error_number == ENOTCONN ||
         error_number == EHOSTUNREACH || error_number == ENETUNREACH;
}

[[noreturn]] void throwErrno(TransportErrorKind kind, const std::string& message,
                             int error_number) {
  throw TransportError(kind, message + ": " + errnoText(error_number));
}

[[noreturn]] void throwIoErrno(const std::string& operation, const std::string& what,
                               int error_number) {
  const TransportErrorKind kind = isDisconnectErrno(error_number)
                                      ? TransportErrorKind::kDisconnected
                                      : TransportErrorKind::kIoError;
  throwErrno(kind, operation + " " + what, error_number);
}

// Returns whether the driver accepted ASYNC_LOW_LATENCY. Ptys and many drivers reject the ioctl
// (ENOTTY/EINVAL): that only means "not supported".
bool requestLowLatency(int fd) {
#if defined(__linux__) && defined(TIOCGSERIAL) && defined(TIOCSSERIAL)
  serial_struct serial_info{};
  if (::ioctl(fd, TIOCGSERIAL, &serial_info) != 0) return false;
  if (serial_info.flags & ASYNC_LOW_LATENCY) return true;
  serial_info.flags |= ASYNC_LOW_LATENCY;
  return ::ioctl(fd, TIOCSSERIAL, &serial_info) == 0;
#else
  (void)fd;
  return false;
#endif
}

void configureRaw8N1(int fd, speed_t speed, const std::string& path) {
  termios settings{};
  if (::tcgetattr(fd, &settings) != 0) {
    throwErrno(TransportErrorKind::kConfigureFailed, "cannot read terminal settings of " + path,
               errno);
  }
  ::cfmakeraw(&settings);
  settings.c_cflag &= ~(CSIZE | PARENB | CSTOPB | CRTSCTS);
  settings.c_cflag |= CS8 | CLOCAL | CREAD;
  settings.c_iflag &= ~(IXON | IXOFF | IXANY);
  // Reads never block (the fd is O_NONBLOCK); timeouts come from the reader's wait, which termios
  // VTIME cannot express below 100 ms. VMIN 1 makes a read with nothing there EAGAIN, as on a
  // socket, where VMIN 0 would return 0, which the reader could not tell from the end of a hung-up
  // tty: a read may come with no new byte announced (ReadWaiter, bytes a full buffer left).
  settings.c_cc[VMIN] = 1;
  settings.c_cc[VTIME] = 0;
  if (::cfsetispeed(&settings, speed) != 0 || ::cfsetospeed(&settings, speed) != 0) {
    throwErrno(TransportErrorKind::kConfigureFailed, "cannot set the baud rate of " + path, errno);
  }
  if (::tcsetattr(fd, TCSANOW, &settings) != 0) {
    throwErrno(TransportErrorKind::kConfigureFailed, "cannot configure " + path, errno);
  }
}

}  // namespace

const std::vector<unsigned>& supportedBaudRates() {
  static const std::vector<unsigned> kRates = {
      1200,   2400,   4800,   9600,    19200,   38400,   57600,   115200,  230400,  250000, 460800,
      500000, 576000, 921600, 1000000, 1152000, 1500000, 2000000, 2500000, 3000000, 3500000, 4000000};
  return kRates;
}

bool isSupportedBaud(unsigned baud) {
  const auto& rates = supportedBaudRates();
  return std::binary_search(rates.begin(), rates.end(), baud);
}

std::string supportedBaudRatesText() {
  std::string text;
  for (unsigned rate : supportedBaudRates()) text += (text.empty() ? "" : ", ") + std::to_string(rate);
  return text;
}

std::optional<unsigned> readBaudRate(int fd) {
  if (const std::optional<unsigned> baud = readBaudWithTermios2(fd)) return baud;
  termios settings{};
  if (::tcgetattr(fd, &settings) != 0) return std::nullopt;
  const speed_t speed = ::cfgetospeed(&settings);
  for (unsigned rate : supportedBaudRates()) {
    if (baudToSpeed(rate) == std::optional<unsigned>(speed)) return rate;
  }
  return std::nullopt;
}

std::optional<unsigned> baudToSpeed(unsigned baud) {
  switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
#ifdef B460800
    case 460800: return B460800;
    case 500000: return B500000;
    case 576000: return B576000;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 1152000: return B1152000;
    case 1500000: return B1500000;
    case 2000000: return B2000000;
    case 2500000: return B2500000;
    case 3000000: return B3000000;
    case 3500000: return B3500000;
    case 4000000: return B4000000;
#endif
    default: return std::nullopt;
  }
}

std::optional<int> readLatencyTimerMs(const std::string& device_path) {
  char resolved[PATH_MAX];
  if (::realpath(device_path.c_str(), resolved) == nullptr) return std::nullopt;
  const std::string device(resolved);
  const std::string tty_name = device.substr(device.find_last_of('/') + 1);
  if (tty_name.empty()) return std::nullopt;
  std::ifstream file("/sys/bus/usb-serial/devices/" + tty_name + "/latency_timer");
  int latency_ms = 0;
  if (!(file >> latency_ms)) return std::nullopt;
  return latency_ms;
}

namespace {

/// A wait on `fd` alone, for the streams nobody wakes (the simulator's end of a pty, the
/// benchmarks' robot): a poll() that sets nothing up beforehand.
Readiness pollOne(int fd, int timeout_ms, const std::string& what) {
  pollfd waiter{fd, POLLIN, 0};
  const int ready = ::poll(&waiter, 1, timeout_ms);
  if (ready < 0) {
    if (errno == EINTR) return Readiness::kTimeout;
    throwIoErrno("poll on", what, errno);
  }
  if (ready == 0) return Readiness::kTimeout;
  if (waiter.revents & POLLNVAL) {
    throw TransportError(TransportErrorKind::kDisconnected, what + " is not open (POLLNVAL)");
  }
  return (waiter.revents & POLLIN) ? Readiness::kInput : Readiness::kHangUp;
}

}  // namespace

std::size_t readFromFd(int fd, uint8_t* buffer, std::size_t capacity, int timeout_ms,
                       const std::string& what, ReadWaiter* waiter) {
  if (fd < 0) throw TransportError(TransportErrorKind::kDisconnected, what + " is not open");
  if (capacity == 0) return 0;
  if (waiter != nullptr && !waiter->valid()) waiter = nullptr;

  for (;;) {
    Readiness readiness = Readiness::kTimeout;
    if (waiter != nullptr) {
      const WaitResult waited = waiter->wait(timeout_ms);
      if (waited.readiness == Readiness::kFailed) throwIoErrno("wait on", what, waited.error);
      readiness = waited.readiness;
    } else {
      readiness = pollOne(fd, timeout_ms, what);
    }
    // Woken: the caller checks why; pending data is read on its next call.
    if (readiness == Readiness::kTimeout || readiness == Readiness::kWoken) return 0;
    if (readiness == Readiness::kHangUp) {
      throw TransportError(TransportErrorKind::kDisconnected, what + " hung up");
    }

    const ssize_t received = ::read(fd, buffer, capacity);
    // A full buffer or an interrupted read may leave bytes that no new arrival announces.
    if (waiter != nullptr &&
        (received == static_cast<ssize_t>(capacity) || (received < 0 && errno == EINTR))) {
      waiter->moreMayBeWaiting();
    }
    if (received > 0) return static_cast<std::size_t>(received);
    if (received == 0) {
      throw TransportError(TransportErrorKind::kDisconnected, what + " reached end of file");
    }
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      throwIoErrno("read from", what, errno);
    }
    if (waiter != nullptr && waiter->hungUp()) {
      throw TransportError(TransportErrorKind::kDisconnected, what + " hung up");
    }
    // Nothing was left after all: wait for the next arrival (that look took no time).
    if (readiness != Readiness::kMaybeInput || errno == EINTR) return 0;
  }
}

void writeAllToFd(int fd, const uint8_t* data, std::size_t size, const std::string& what,
                  std::chrono::milliseconds stall_limit, FdKind kind) {
  if (fd < 0) throw TransportError(TransportErrorKind::kDisconnected, what + " is not open");
  using Clock = std::chrono::steady_clock;
  std::size_t written = 0;
  auto last_progress = Clock::now();
  while (written < size) {
    const ssize_t count = kind == FdKind::kSocket
                              ? ::send(fd, data + written, size - written, MSG_NOSIGNAL)
                              : ::write(fd, data + written, size - written);
    if (count > 0) {
      written += static_cast<std::size_t>(count);
      last_progress = Clock::now();
      continue;
    }
    if (count < 0 && errno == EINTR) continue;
    if (count < 0 && errno != EAGAIN && errno != EWOULDBLOCK) throwIoErrno("write to", what, errno);

    // Output buffer full: wait for room, but not forever (flow stalled, adapter wedged).
    const auto stalled =
        std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - last_progress);
    const auto remaining = stall_limit - stalled;
    if (remaining.count() <= 0) {
      throw TransportError(TransportErrorKind::kIoError, "write to " + what + " timed out after " +
                                                             std::to_string(written) + " of " +
                                                             std::to_string(size) + " bytes");
    }
    pollfd waiter{fd, POLLOUT, 0};
    const int ready = ::poll(&waiter, 1, static_cast<int>(remaining.count()));
    if (ready < 0 && errno != EINTR) throwIoErrno("poll on", what, errno);
    if (ready > 0 && (waiter.revents & (POLLHUP | POLLERR | POLLNVAL)) &&
        !(waiter.revents & POLLOUT)) {
      throw TransportError(TransportErrorKind::kDisconnected, what + " hung up during write");
    }
  }
}

namespace {

bool processExists(long pid) {
  return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
}

/// The pid in a UUCP lock file (ASCII, or a binary int from old programs); nullopt when unreadable.
std::optional<long> readLockFilePid(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  std::string content((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (content.size() == sizeof(int) &&
      (content[0] != ' ' && (content[0] < '0' || content[0] > '9'))) {
    int binary_pid = 0;
    std::memcpy(&binary_pid, content.data(), sizeof(int));
    return binary_pid;
  }
  char* end = nullptr;
  const long pid = std::strtol(content.c_str(), &end, 10);
  if (end == content.c_str()) return std::nullopt;
  return pid;
}

}  // namespace

std::optional<PortHolder> findPortHolder(const std::string& device_path) {
  // 1. A UUCP lock file (minicom, screen and ModemManager's neighbours write these).
  const std::string name = device_path.substr(device_path.find_last_of('/') + 1);
  char resolved[PATH_MAX];
  const std::string real_name =
      ::realpath(device_path.c_str(), resolved)
          ? std::string(resolved).substr(std::string(resolved).find_last_of('/') + 1)
          : name;
  for (const char* dir : {"/run/lock", "/var/lock"}) {
    const std::string lock_file = std::string(dir) + "/LCK.." + real_name;
    const std::optional<long> pid = readLockFilePid(lock_file);
    if (pid && *pid != ::getpid() && processExists(*pid)) return PortHolder{*pid, lock_file};
  }
  // 2. An flock or POSIX lock on the device's inode: /proc/locks lines read
  //    "1: FLOCK  ADVISORY  WRITE 1234 00:18:3 0 EOF" (pid, then major:minor:inode, hex:hex:dec).
  struct stat device {};
  if (::stat(device_path.c_str(), &device) != 0) return std::nullopt;
  std::ifstream locks("/proc/locks");
  std::string line;
  while (std::getline(locks, line)) {
    std::istringstream fields(line);
    std::string ordinal, kind, mode, access, where;
    long pid = 0;
    if (!(fields >> ordinal >> kind)) continue;
    if (kind == "->") fields >> kind;  // a blocked waiter: "1: -> FLOCK ..."
    if (!(fields >> mode >> access >> pid >> where)) continue;
    unsigned major_number = 0, minor_number = 0;
    unsigned long inode = 0;
    if (std::sscanf(where.c_str(), "%x:%x:%lu", &major_number, &minor_number, &inode) != 3)
      continue;
    if (inode == device.st_ino && major_number == major(device.st_dev) &&
        minor_number == minor(device.st_dev) && pid != ::getpid()) {
      return PortHolder{pid, "/proc/locks"};
    }
  }
  return std::nullopt;
}

namespace {

[[noreturn]] void throwPortBusy(const std::string& path, const std::string& how) {
  std::string message = "port busy: " + path + " is " + how + " by another process";
  if (const std::optional<PortHolder> holder = findPortHolder(path)) {
    message += " (pid " + std::to_string(holder->pid) + ", from " + holder->source + ")";
  }
  throw TransportError(TransportErrorKind::kOpenFailed, message);
}

/// Takes the port for this process alone: an advisory flock (which other instances of this driver
/// and lock-aware programs honour) and TIOCEXCL (further opens fail with EBUSY, except for root).
/// A pty or a driver refusing TIOCEXCL is "not supported", not an error.
void takeExclusively(int fd, const std::string& path) {
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error_number = errno;
    ::close(fd);
    if (error_number == EWOULDBLOCK) throwPortBusy(path, "locked");
    throwErrno(TransportErrorKind::kOpenFailed, "cannot lock " + path, error_number);
  }
  // Our flock succeeded, yet another process may hold a UUCP lock file or a POSIX (fcntl) lock,
  // which do not conflict with flock: respect those too.
  if (findPortHolder(path)) {
    ::close(fd);
    throwPortBusy(path, "locked");
  }
  (void)::ioctl(fd, TIOCEXCL);  // ENOTTY/EINVAL where unsupported: the flock still protects us
}

}  // namespace

SerialPort::SerialPort(SerialPortOptions options) : options_(std::move(options)) {}

SerialPort::~SerialPort() { close(); }

void SerialPort::open() {
  close();
  if (!isSupportedBaud(options_.baud)) {
    throw TransportError(TransportErrorKind::kConfigureFailed,
                         "unsupported baud rate " + std::to_string(options_.baud) + " for " +
                             options_.path + " (supported: " + supportedBaudRatesText() + ")");
  }
  // A rate without a Bxxx constant: configured at B38400 first, then set by number.
  const std::optional<unsigned> speed = baudToSpeed(options_.baud);

  const int fd = ::open(options_.path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0 && errno == EBUSY) throwPortBusy(options_.path, "opened exclusively");
  if (fd < 0) throwErrno(TransportErrorKind::kOpenFailed, "cannot open " + options_.path, errno);
  takeExclusively(fd, options_.path);  // closes fd when it throws

  try {
    configureRaw8N1(fd, speed.value_or(B38400), options_.path);
    if (!speed) {
      const int error = setBaudWithTermios2(fd, options_.baud);
      if (error != 0) {
        throwErrno(TransportErrorKind::kConfigureFailed,
                   "cannot set the baud rate " + std::to_string(options_.baud) + " of " + options_.path,
                   error);
      }
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  // Bytes queued before we attached belong to nobody's request: drop them.
  ::tcflush(fd, TCIOFLUSH);
  low_latency_ = requestLowLatency(fd);
  latency_timer_ms_ = readLatencyTimerMs(options_.path);
  if (const int error = waiter_.watch(fd)) {
    ::close(fd);
    throwErrno(TransportErrorKind::kOpenFailed, "cannot wait for input on " + options_.path, error);
  }
  fd_ = fd;
}

void SerialPort::close() {
  const int fd = fd_.exchange(-1);
  if (fd >= 0) {
    waiter_.unwatch(fd);
    // The exclusive flag outlives this fd while another one (a simulator's pty end) stays open.
    (void)::ioctl(fd, TIOCNXCL);
    ::close(fd);  // releases the flock
  }
  low_latency_ = false;
  latency_timer_ms_.reset();
}

std::size_t SerialPort::read(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  return readFromFd(fd_, buffer, capacity, timeout_ms, options_.path, &waiter_);
}

void SerialPort::write(const uint8_t* data, std::size_t size) {
  writeAllToFd(fd_, data, size, options_.path);
}

}  // namespace serial_robot_driver::transport
