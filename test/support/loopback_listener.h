// A socket listening on 127.0.0.1 at a port the kernel picks: the network serial server's end that
// the TCP transport's tests and driver_bench's TCP sessions play. Header-only: driver_bench takes it
// without the test support library.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace test_support {

struct LoopbackListener {
  int fd = -1;  ///< the listening socket; the caller closes it
  uint16_t port = 0;
  std::string url() const { return "tcp://127.0.0.1:" + std::to_string(port); }
};

/// \throws std::runtime_error with errno's text when the socket cannot listen.
inline LoopbackListener listenOnLoopback(int backlog) {
  LoopbackListener listener;
  listener.fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(address);
  const bool ok = listener.fd >= 0 &&
                  ::bind(listener.fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
                  ::listen(listener.fd, backlog) == 0 &&
                  ::getsockname(listener.fd, reinterpret_cast<sockaddr*>(&address), &length) == 0;
  if (!ok) {
    const std::string error = std::strerror(errno);
    if (listener.fd >= 0) ::close(listener.fd);
    throw std::runtime_error("cannot listen on 127.0.0.1: " + error);
  }
  listener.port = ntohs(address.sin_port);
  return listener;
}

}  // namespace test_support
