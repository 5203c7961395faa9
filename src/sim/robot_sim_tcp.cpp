#include "robot_sim_tcp.h"

#include <linux/sockios.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include "serial_robot_driver/transport/byte_stream.h"
#include "serial_robot_driver/transport/tcp_stream.h"

namespace serial_robot_driver::sim::detail {

namespace {

using transport::TransportError;
using transport::TransportErrorKind;

[[noreturn]] void throwListenFailed(const std::string& url, const std::string& problem) {
  throw TransportError(TransportErrorKind::kOpenFailed,
                       "robot_sim: cannot listen on " + url + ": " + problem);
}

/// A non-blocking listening socket bound to `address`, or -1 with errno set.
int listenOn(const addrinfo& address) {
  const int fd = ::socket(address.ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  const int on = 1;
  // A replug rebinds the port at once, though the connection it closed is still in TIME_WAIT.
  (void)::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof(on));
  if (::bind(fd, address.ai_addr, address.ai_addrlen) != 0 || ::listen(fd, 1) != 0) {
    const int error = errno;
    ::close(fd);
    errno = error;
    return -1;
  }
  return fd;
}

/// The port `fd` is bound to.
uint16_t boundPort(int fd) {
  sockaddr_storage address{};
  socklen_t size = sizeof(address);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) return 0;
  const auto* v4 = reinterpret_cast<const sockaddr_in*>(&address);
  const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&address);
  return ntohs(address.ss_family == AF_INET6 ? v6->sin6_port : v4->sin_port);
}

}  // namespace

TcpListener::TcpListener(const std::string& url) {
  std::string problem;
  const std::optional<transport::TcpAddress> address = transport::parseTcpUrl(url, &problem, true);
  if (!address) throwListenFailed(url, problem);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV | AI_PASSIVE;
  addrinfo* found = nullptr;
  const int lookup =
      ::getaddrinfo(address->host.c_str(), std::to_string(address->port).c_str(), &hints, &found);
  if (lookup != 0) throwListenFailed(url, ::gai_strerror(lookup));
  const std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> addresses(found, ::freeaddrinfo);
  listen_fd_ = listenOn(*found);
  if (listen_fd_ < 0) throwListenFailed(url, std::strerror(errno));
  const bool bracketed = address->host.find(':') != std::string::npos;
  url_ = "tcp://" + (bracketed ? "[" + address->host + "]" : address->host) + ":" +
         std::to_string(boundPort(listen_fd_));
}

TcpListener::~TcpListener() {
  dropClient();
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

bool TcpListener::accept() {
  if (client_fd_ >= 0) return false;
  client_fd_ = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (client_fd_ < 0) return false;
  const int on = 1;
  (void)::setsockopt(client_fd_, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
  return true;
}

void TcpListener::dropClient() {
  if (client_fd_ < 0) return;
  ::close(client_fd_);
  client_fd_ = -1;
}

ssize_t TcpListener::send(const uint8_t* data, std::size_t size) const {
  return ::send(client_fd_, data, size, MSG_NOSIGNAL);
}

bool TcpListener::allSent() const {
  int unsent = 0;
  return client_fd_ < 0 || (::ioctl(client_fd_, SIOCOUTQ, &unsent) == 0 && unsent == 0);
}

}  // namespace serial_robot_driver::sim::detail
