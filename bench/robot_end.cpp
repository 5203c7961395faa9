// The robot's end of the line a benchmark plays the robot on (see the header).
#include "robot_end.h"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <stdexcept>

#include "bench_support.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/transport/serial_port.h"
#include "support/loopback_listener.h"

namespace serial_robot_driver::bench {

std::string transportName(Transport transport) {
  return transport == Transport::kTcp ? "tcp" : "pty";
}

namespace {

/// The master side of a pseudo-terminal; the program opens the slave through the link.
class PtyRobotEnd : public RobotEnd {
 public:
  explicit PtyRobotEnd(const std::string& link_path) : pty_(link_path) {}
  std::string port() const override { return pty_.linkPath(); }
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override {
    return pty_.read(buffer, capacity, timeout_ms);
  }
  bool writeFrame(const std::vector<uint8_t>& frame) override {
    return writeFrameOrDrop(pty_, frame);
  }

 private:
  sim::PseudoTerminal pty_;
};

/// A listener on 127.0.0.1 (ephemeral port) and the one connection the program makes to it.
class TcpRobotEnd : public RobotEnd {
 public:
  TcpRobotEnd() {
    const test_support::LoopbackListener listener = test_support::listenOnLoopback(1);
    listener_ = listener.fd;
    url_ = listener.url();
  }

  ~TcpRobotEnd() override {
    if (connection_ >= 0) ::close(connection_);
    for (int retired : retired_) ::close(retired);
    ::close(listener_);
  }

  std::string port() const override { return url_; }

  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override {
    const int connection = connection_;
    if (connection < 0) {
      acceptWithin(timeout_ms);
      return 0;
    }
    try {
      return transport::readFromFd(connection, buffer, capacity, timeout_ms, port());
    } catch (const transport::TransportError&) {
      retire(connection);  // the program closed it: wait for the next one
      return 0;
    }
  }

  bool writeFrame(const std::vector<uint8_t>& frame) override {
    const int connection = connection_;
    if (connection < 0) return false;
    ssize_t written;
    do {
      written = ::send(connection, frame.data(), frame.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
    } while (written < 0 && errno == EINTR);
    return written == static_cast<ssize_t>(frame.size());
  }

 private:
  void acceptWithin(int timeout_ms) {
    pollfd waiter{listener_, POLLIN, 0};
    if (::poll(&waiter, 1, timeout_ms) <= 0) return;
    const int connection = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
    if (connection < 0) return;
    // The robot's frames go out as written, as a UART would send them.
    const int on = 1;
    ::setsockopt(connection, IPPROTO_TCP, TCP_NODELAY, &on, sizeof(on));
    connection_ = connection;
  }

  /// Kept open until destruction rather than closed: a writer may still hold its number.
  void retire(int connection) {
    connection_ = -1;
    retired_.push_back(connection);
  }

  int listener_ = -1;
  std::string url_;
  std::atomic<int> connection_{-1};
  std::vector<int> retired_;  ///< reader thread only
};

}  // namespace

std::unique_ptr<RobotEnd> openRobotEnd(Transport transport, const std::string& link_path) {
  if (transport == Transport::kTcp) return std::make_unique<TcpRobotEnd>();
  return std::make_unique<PtyRobotEnd>(link_path);
}

}  // namespace serial_robot_driver::bench
