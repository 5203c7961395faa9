// A serial line reached over TCP: a network serial server (ser2net in raw mode, a Moxa or USR
// device server, an ESP32 bridge) passes the bytes of its serial port to and from one TCP
// connection. The port parameters take it as `tcp://HOST:PORT` instead of a device path.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "serial_robot_driver/transport/byte_stream.h"
#include "serial_robot_driver/transport/serial_port.h"

namespace serial_robot_driver::transport {

/// Where a `tcp://` port connects to.
struct TcpAddress {
  std::string host;  ///< a host name, an IPv4 address or an IPv6 address (without its brackets)
  uint16_t port = 0;
};

/// Whether a port parameter names a TCP connection (starts with "tcp://") rather than a device.
bool isTcpUrl(const std::string& path);

/// Parses "tcp://HOST:PORT": HOST is a host name, an IPv4 address or an IPv6 address in brackets
/// ("tcp://[::1]:4001"), PORT 1..65535. Nullopt for anything else, with `problem` (when given)
/// saying what is wrong, e.g. "port must be 1-65535". `any_port`: port 0 is taken too (a
/// listener's "any free port"; robot_sim).
std::optional<TcpAddress> parseTcpUrl(const std::string& url, std::string* problem = nullptr,
                                      bool any_port = false);

/// Threading as SerialPort: one thread may read while another writes; open() and close() must not
/// race with either. The baud rate means nothing here: the server sets its serial line's.
class TcpStream : public ByteStream {
 public:
  /// `url` as parseTcpUrl() takes it; a malformed one fails in open() (kOpenFailed).
  explicit TcpStream(std::string url);
  ~TcpStream() override;
  TcpStream(const TcpStream&) = delete;
  TcpStream& operator=(const TcpStream&) = delete;

  /// Resolves the host and connects, waiting at most ~2 s in all (the reader thread opens the
  /// port, so it must not hang there). The connection sends each write at once (TCP_NODELAY) and
  /// notices a peer that went silent within a few seconds (keepalive and TCP_USER_TIMEOUT), so a
  /// pulled cable at the server is a lost port as on a serial line. Reopens when already open.
  /// \throws TransportError kOpenFailed: a malformed URL, an unknown host, the connection refused
  ///         or timed out.
  void open() override;
  /// Idempotent; the destructor calls it.
  void close() override;
  bool isOpen() const override { return fd_ >= 0; }
  /// \throws TransportError kDisconnected when the peer closed, reset or timed out the connection
  ///         (and when not open), kIoError for other failures.
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  /// \throws TransportError kDisconnected when the connection is gone (and when not open),
  ///         kIoError when the peer accepts nothing for ~100 ms or the send fails otherwise.
  void write(const uint8_t* data, std::size_t size) override;
  std::string name() const override { return url_; }

  bool wakeable() const override { return waiter_.valid(); }
  void wakeRead() override { waiter_.wake(); }

 private:
  std::string url_;
  std::atomic<int> fd_{-1};
  ReadWaiter waiter_;
};

}  // namespace serial_robot_driver::transport
