// RobotSim's stand-in for a network serial server (ser2net, a device server): a port whose link is
// a tcp:// URL is served on a listening socket instead of a pty, one client at a time.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace serial_robot_driver::sim::detail {

/// Listens on the URL's address (port 0: one the kernel picks; url() tells which). A client that
/// connects while another is attached waits in the listen queue until the first one is gone.
class TcpListener {
 public:
  /// \throws transport::TransportError kOpenFailed for a malformed URL or a failed bind/listen.
  explicit TcpListener(const std::string& url);
  ~TcpListener();
  TcpListener(const TcpListener&) = delete;
  TcpListener& operator=(const TcpListener&) = delete;

  /// "tcp://HOST:PORT" with the port actually bound.
  const std::string& url() const { return url_; }
  int listenFd() const { return listen_fd_; }
  /// The attached client's socket, -1 when none.
  int clientFd() const { return client_fd_; }
  /// Takes a waiting client when none is attached; whether one was attached now.
  bool accept();
  /// Closes the client's connection (it reads EOF), as a server whose line went away.
  void dropClient();
  /// Sends what the socket takes now (never blocks, never raises SIGPIPE); -1 and errno as send.
  ssize_t send(const uint8_t* data, std::size_t size) const;
  /// Whether everything sent has been acknowledged by the client's side (nothing in flight).
  bool allSent() const;

 private:
  int listen_fd_ = -1;
  int client_fd_ = -1;
  std::string url_;
};

}  // namespace serial_robot_driver::sim::detail
