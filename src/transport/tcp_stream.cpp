#include "serial_robot_driver/transport/tcp_stream.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <memory>
#include <utility>

namespace serial_robot_driver::transport {

namespace {

constexpr char kScheme[] = "tcp://";
constexpr std::size_t kSchemeLength = sizeof(kScheme) - 1;
/// The whole open(), every address of the host included: the reader thread waits here.
constexpr std::chrono::milliseconds kConnectTimeout{2000};
/// A silent peer (cable pulled at the server, server powered off) is given up on after about
/// kKeepIdleS + kKeepProbes * kKeepIntervalS s while idle, or kUserTimeoutMs when sent bytes stay
/// unacknowledged (the driver writes at its loop rate, so this one usually fires first).
constexpr int kKeepIdleS = 2;
constexpr int kKeepIntervalS = 1;
constexpr int kKeepProbes = 2;
constexpr unsigned kUserTimeoutMs = 4000;
constexpr std::size_t kLongestHostName = 253;

/// A piece of a (possibly hostile, huge) URL short enough to quote in a message.
std::string quoted(const std::string& text) {
  constexpr std::size_t kLongest = 40;
  return "'" + (text.size() <= kLongest ? text : text.substr(0, kLongest) + "...") + "'";
}

/// Why `host` (not bracketed) cannot be connected to, or "".
std::string hostProblem(const std::string& host) {
  if (host.empty()) return "the host is empty";
  if (host.find(':') != std::string::npos) {
    return "an IPv6 address must be in brackets (tcp://[::1]:4001)";
  }
  if (host.size() > kLongestHostName) return "the host is longer than a host name may be (253)";
  const char* const kHostCharacters =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789.-_";
  if (host.find_first_not_of(kHostCharacters) != std::string::npos) {
    return "the host " + quoted(host) + " is neither an address nor a host name";
  }
  in_addr address{};
  if (host.find_first_not_of("0123456789.") == std::string::npos &&
      ::inet_pton(AF_INET, host.c_str(), &address) != 1) {
    return "the host " + quoted(host) + " is not an IPv4 address (a.b.c.d, each 0-255)";
  }
  return "";
}

/// Why `text` is no port 1..65535 (0.. with `any_port`), or "" with `port` set.
std::string portProblem(const std::string& text, bool any_port, uint16_t* port) {
  if (text.empty()) return "the port is missing (tcp://HOST:PORT)";
  if (text.size() > 5 || text.find_first_not_of("0123456789") != std::string::npos) {
    return "port must be 1-65535 (got " + quoted(text) + ")";
  }
  const unsigned long value = std::stoul(text);
  if (value > 65535 || (value == 0 && !any_port)) return "port must be 1-65535";
  *port = static_cast<uint16_t>(value);
  return "";
}

/// Splits what follows "tcp://" into host and port text; returns the problem, or "".
std::string splitHostPort(const std::string& rest, std::string* host, std::string* port_text) {
  if (rest.empty()) return "the host and port are missing (tcp://HOST:PORT)";
  if (rest.front() == '[') {
    const std::size_t close = rest.find(']');
    if (close == std::string::npos) return "the IPv6 address has no closing ']'";
    *host = rest.substr(1, close - 1);
    in6_addr address{};
    if (::inet_pton(AF_INET6, host->c_str(), &address) != 1) {
      return quoted("[" + *host + "]") + " is not an IPv6 address";
    }
    const std::string after = rest.substr(close + 1);
    if (after.empty()) return "the port is missing (tcp://[ADDRESS]:PORT)";
    if (after.front() != ':') return "expected ':PORT' after ']'";
    *port_text = after.substr(1);
    return "";
  }
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string::npos) return "the port is missing (tcp://HOST:PORT)";
  *host = rest.substr(0, colon);
  *port_text = rest.substr(colon + 1);
  return hostProblem(*host);
}

[[noreturn]] void throwOpenFailed(const std::string& url, const std::string& problem) {
  throw TransportError(TransportErrorKind::kOpenFailed,
                       "cannot connect to " + url + ": " + problem);
}

/// A connection to a free local port can meet itself (TCP simultaneous open, when the kernel
/// picks the target as the ephemeral port): that is nobody at the other end.
bool connectedToItself(int fd) {
  sockaddr_storage local{}, peer{};
  socklen_t local_size = sizeof(local), peer_size = sizeof(peer);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &local_size) != 0 ||
      ::getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &peer_size) != 0) {
    return false;
  }
  return local_size == peer_size && std::memcmp(&local, &peer, local_size) == 0;
}

/// Waits until `deadline` for the non-blocking connect on `fd` to finish; 0 or an errno.
int awaitConnect(int fd, std::chrono::steady_clock::time_point deadline) {
  while (true) {
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return ETIMEDOUT;
    pollfd waiter{fd, POLLOUT, 0};
    const int ready = ::poll(&waiter, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return errno;
    if (ready == 0) return ETIMEDOUT;
    int error = 0;
    socklen_t size = sizeof(error);
    if (::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size) != 0) return errno;
    if (error == 0 && connectedToItself(fd)) return ECONNREFUSED;
    return error;
  }
}

/// A connected socket to `address`, or -1 with `error` (an errno) set.
int connectTo(const addrinfo& address, std::chrono::steady_clock::time_point deadline, int* error) {
  const int fd =
      ::socket(address.ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, address.ai_protocol);
  if (fd < 0) {
    *error = errno;
    return -1;
  }
  *error = ::connect(fd, address.ai_addr, address.ai_addrlen) == 0 ? 0 : errno;
  if (*error == EINPROGRESS) *error = awaitConnect(fd, deadline);
  if (*error == 0) return fd;
  ::close(fd);
  return -1;
}

/// Latency and loss detection: every write leaves at once (no Nagle delay waiting for more bytes),
/// and a peer that went silent is noticed in seconds, not the kernel's default two hours.
void configureSocket(int fd) {
  const int on = 1;
  (void)::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
  (void)::setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof(on));
  (void)::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &kKeepIdleS, sizeof(kKeepIdleS));
  (void)::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &kKeepIntervalS, sizeof(kKeepIntervalS));
  (void)::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &kKeepProbes, sizeof(kKeepProbes));
  (void)::setsockopt(fd, IPPROTO_TCP, TCP_USER_TIMEOUT, &kUserTimeoutMs, sizeof(kUserTimeoutMs));
}

}  // namespace

bool isTcpUrl(const std::string& path) { return path.compare(0, kSchemeLength, kScheme) == 0; }

std::optional<TcpAddress> parseTcpUrl(const std::string& url, std::string* problem, bool any_port) {
  std::string why;
  TcpAddress address;
  std::string port_text;
  if (!isTcpUrl(url)) {
    why = "must start with tcp://";
  } else {
    why = splitHostPort(url.substr(kSchemeLength), &address.host, &port_text);
    if (why.empty()) why = portProblem(port_text, any_port, &address.port);
  }
  if (why.empty()) return address;
  if (problem) *problem = why;
  return std::nullopt;
}

TcpStream::TcpStream(std::string url) : url_(std::move(url)) {}

TcpStream::~TcpStream() { close(); }

void TcpStream::open() {
  close();
  std::string problem;
  const std::optional<TcpAddress> address = parseTcpUrl(url_, &problem);
  if (!address) throwOpenFailed(url_, problem);

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const int lookup =
      ::getaddrinfo(address->host.c_str(), std::to_string(address->port).c_str(), &hints, &found);
  if (lookup != 0) {
    throwOpenFailed(url_,
                    "unknown host " + quoted(address->host) + " (" + ::gai_strerror(lookup) + ")");
  }
  const std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> addresses(found, ::freeaddrinfo);

  const auto deadline = std::chrono::steady_clock::now() + kConnectTimeout;
  int error = ETIMEDOUT;
  for (const addrinfo* candidate = found; candidate != nullptr; candidate = candidate->ai_next) {
    const int fd = connectTo(*candidate, deadline, &error);
    if (fd >= 0) {
      configureSocket(fd);
      if (const int watch_error = waiter_.watch(fd)) {
        ::close(fd);
        throwOpenFailed(url_, "cannot wait for input: " + std::string(std::strerror(watch_error)));
      }
      fd_ = fd;
      return;
    }
  }
  throwOpenFailed(url_, error == ETIMEDOUT
                            ? "timed out after " + std::to_string(kConnectTimeout.count()) + " ms"
                            : std::string(std::strerror(error)));
}

void TcpStream::close() {
  const int fd = fd_.exchange(-1);
  if (fd < 0) return;
  waiter_.unwatch(fd);
  ::close(fd);
}

std::size_t TcpStream::read(uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  return readFromFd(fd_, buffer, capacity, timeout_ms, url_, &waiter_);
}

void TcpStream::write(const uint8_t* data, std::size_t size) {
  writeAllToFd(fd_, data, size, url_, std::chrono::milliseconds(100), FdKind::kSocket);
}

}  // namespace serial_robot_driver::transport
