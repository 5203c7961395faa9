// Serial ports reached over TCP (tcp://HOST:PORT, a network serial server): the URL parser's
// extremes, TcpStream against a loopback listener made here, and SerialLink reconnecting over TCP
// after the server dropped it.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/transport/tcp_stream.h"
#include "support/framer_configs.h"
#include "support/golden_frames.h"
#include "support/loopback_listener.h"
#include "support/test_helpers.h"
#include "support/transport_fixture.h"

namespace serial_robot_driver::transport {
namespace {

using test_support::waitFor;
using transport_test::allByteValues;
using transport_test::Bytes;
using transport_test::errorKindOf;
using transport_test::kPatientTimeoutMs;
using transport_test::readExactly;
using transport_test::writeBytes;

constexpr double kWaitSeconds = 5.0;  // generous: the machine may be busy

// --- tcp:// URLs -----------------------------------------------------------------------------

struct GoodUrl {
  std::string url, host;
  uint16_t port;
};

class TcpUrlGood : public ::testing::TestWithParam<GoodUrl> {};

TEST_P(TcpUrlGood, ParsesHostAndPort) {
  std::string problem;
  const std::optional<TcpAddress> address = parseTcpUrl(GetParam().url, &problem);
  ASSERT_TRUE(address.has_value()) << GetParam().url << ": " << problem;
  EXPECT_EQ(address->host, GetParam().host);
  EXPECT_EQ(address->port, GetParam().port);
  EXPECT_TRUE(isTcpUrl(GetParam().url));
}

INSTANTIATE_TEST_SUITE_P(Cases, TcpUrlGood,
                         ::testing::Values(GoodUrl{"tcp://127.0.0.1:4001", "127.0.0.1", 4001},
                                           GoodUrl{"tcp://localhost:1", "localhost", 1},
                                           GoodUrl{"tcp://ser2net-box.lan:65535", "ser2net-box.lan",
                                                   65535},
                                           GoodUrl{"tcp://[::1]:2000", "::1", 2000},
                                           GoodUrl{"tcp://[fe80::2:1]:23", "fe80::2:1", 23},
                                           GoodUrl{"tcp://10.0.0.7:00080", "10.0.0.7", 80}));

struct BadUrl {
  std::string url;
  std::string problem;  ///< a part of the message
};

class TcpUrlBad : public ::testing::TestWithParam<BadUrl> {};

TEST_P(TcpUrlBad, IsRefusedSayingWhy) {
  std::string problem;
  EXPECT_FALSE(parseTcpUrl(GetParam().url, &problem).has_value());
  EXPECT_NE(problem.find(GetParam().problem), std::string::npos) << problem;
  EXPECT_LT(problem.size(), 200u) << "a hostile URL must not flood the log";
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TcpUrlBad,
    ::testing::Values(
        BadUrl{"", "must start with tcp://"}, BadUrl{"/dev/ttyUSB0", "must start with tcp://"},
        BadUrl{"TCP://host:1", "must start with tcp://"},
        BadUrl{"tcp://", "the host and port are missing"},
        BadUrl{"tcp://:4001", "the host is empty"}, BadUrl{"tcp://host", "the port is missing"},
        BadUrl{"tcp://host:", "the port is missing"}, BadUrl{"tcp://host:0", "1-65535"},
        BadUrl{"tcp://host:65536", "1-65535"}, BadUrl{"tcp://host:99999", "1-65535"},
        BadUrl{"tcp://host:abc", "1-65535"}, BadUrl{"tcp://host:-1", "1-65535"},
        BadUrl{"tcp://host:4001/", "1-65535"}, BadUrl{"tcp://host:4001 ", "1-65535"},
        BadUrl{"tcp://host:" + std::string(100000, '9'), "1-65535"},
        BadUrl{"tcp://::1:4001", "in brackets"}, BadUrl{"tcp://[::1]", "the port is missing"},
        BadUrl{"tcp://[::1:4001", "no closing ']'"}, BadUrl{"tcp://[]:4001", "not an IPv6"},
        BadUrl{"tcp://[zz::1]:4001", "not an IPv6"}, BadUrl{"tcp://[::1]4001", "':PORT'"},
        BadUrl{"tcp://256.0.0.1:4001", "not an IPv4"}, BadUrl{"tcp://1.2.3:4001", "not an IPv4"},
        BadUrl{"tcp://ho st:4001", "neither an address nor a host name"},
        BadUrl{"tcp://host/x:4001", "neither an address nor a host name"},
        BadUrl{std::string("tcp://ho\0st:1", 13), "neither an address nor a host name"},
        BadUrl{"tcp://" + std::string(300, 'a') + ":4001", "longer than a host name"},
        BadUrl{"tcp://" + std::string(100000, '[') + ":4001", "no closing ']'"}));

TEST(TcpUrl, OnlyTheTcpSchemeIsAUrl) {
  EXPECT_FALSE(isTcpUrl("/dev/ttyUSB0"));
  EXPECT_FALSE(isTcpUrl("tcp:/host:1"));
  EXPECT_FALSE(isTcpUrl(""));
  EXPECT_TRUE(isTcpUrl("tcp://"));
}

// --- a loopback server for the stream --------------------------------------------------------

/// Listens on 127.0.0.1 at a port the kernel picks and plays the network serial server.
class LoopbackServer {
 public:
  LoopbackServer() {
    const test_support::LoopbackListener listener = test_support::listenOnLoopback(4);
    listen_fd_ = listener.fd;
    url_ = listener.url();
  }
  ~LoopbackServer() {
    closeClient();
    closeListener();
  }
  const std::string& url() const { return url_; }
  /// Takes the next client (waits for it); false when none came.
  bool accept() {
    closeClient();
    pollfd waiter{listen_fd_, POLLIN, 0};
    if (::poll(&waiter, 1, kPatientTimeoutMs) != 1) return false;
    client_fd_ = ::accept(listen_fd_, nullptr, nullptr);
    return client_fd_ >= 0;
  }
  void send(const Bytes& bytes) {
    ASSERT_EQ(::send(client_fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(bytes.size()));
  }
  /// Up to `count` bytes the client wrote (fewer when they stop coming).
  Bytes receive(std::size_t count) {
    Bytes received;
    uint8_t chunk[512];
    while (received.size() < count) {
      pollfd waiter{client_fd_, POLLIN, 0};
      if (::poll(&waiter, 1, kPatientTimeoutMs) != 1) break;
      const ssize_t got =
          ::recv(client_fd_, chunk, std::min(sizeof(chunk), count - received.size()), 0);
      if (got <= 0) break;
      received.insert(received.end(), chunk, chunk + got);
    }
    return received;
  }
  void closeClient() {
    if (client_fd_ >= 0) ::close(client_fd_);
    client_fd_ = -1;
  }
  void closeListener() {
    if (listen_fd_ >= 0) ::close(listen_fd_);
    listen_fd_ = -1;
  }

 private:
  int listen_fd_ = -1;
  int client_fd_ = -1;
  std::string url_;
};

/// A URL nobody listens on: a port the kernel handed out and that was closed again.
std::string refusedUrl() {
  LoopbackServer server;
  return server.url();
}

// --- TcpStream -------------------------------------------------------------------------------

/// A TcpStream connected to a loopback server that has accepted it.
class ConnectedTcpStream : public ::testing::Test {
 protected:
  void SetUp() override {
    stream.open();
    ASSERT_TRUE(server.accept());
  }
  LoopbackServer server;
  TcpStream stream{server.url()};
};

TEST_F(ConnectedTcpStream, CarriesEveryByteValueBothWays) {
  EXPECT_TRUE(stream.isOpen());
  EXPECT_EQ(stream.name(), server.url());

  const Bytes bytes = allByteValues();
  writeBytes(stream, bytes);
  EXPECT_EQ(server.receive(bytes.size()), bytes);
  server.send(bytes);
  EXPECT_EQ(readExactly(stream, bytes.size()), bytes);
}

TEST_F(ConnectedTcpStream, AFrameSplitAcrossWritesArrivesWhole) {
  const Bytes& frame = golden::base::kBattery87ReplySeq0;
  const Bytes head(frame.begin(), frame.begin() + 3);
  const Bytes tail(frame.begin() + 3, frame.end());
  server.send(head);
  EXPECT_EQ(readExactly(stream, head.size()), head) << "what came so far is delivered";
  server.send(tail);
  EXPECT_EQ(readExactly(stream, tail.size()), tail);
}

TEST_F(ConnectedTcpStream, ThePeerClosingIsADisconnectOnRead) {
  server.closeClient();
  uint8_t buffer[8];
  EXPECT_EQ(errorKindOf([&] { stream.read(buffer, sizeof(buffer), kPatientTimeoutMs); }),
            TransportErrorKind::kDisconnected);
}

TEST_F(ConnectedTcpStream, ThePeerClosingIsADisconnectOnWriteNotASignal) {
  server.closeClient();
  // The first writes may still be taken by the kernel; the peer's reset fails a later one, and
  // without MSG_NOSIGNAL the SIGPIPE would end this process.
  std::optional<TransportErrorKind> failure;
  ASSERT_TRUE(waitFor(
      [&] {
        try {
          writeBytes(stream, golden::base::kResetSeq2);
        } catch (const TransportError& error) {
          failure = error.kind();
        }
        return failure.has_value();
      },
      kWaitSeconds));
  EXPECT_EQ(*failure, TransportErrorKind::kDisconnected);
}

TEST(TcpStream, ARefusedConnectionIsAnOpenFailureSayingSo) {
  TcpStream stream(refusedUrl());
  try {
    stream.open();
    FAIL() << "connected to a port nobody listens on";
  } catch (const TransportError& error) {
    EXPECT_EQ(error.kind(), TransportErrorKind::kOpenFailed);
    EXPECT_NE(std::string(error.what()).find(std::strerror(ECONNREFUSED)), std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find(stream.name()), std::string::npos) << error.what();
  }
  EXPECT_FALSE(stream.isOpen());
}

TEST(TcpStream, AMalformedOrUnknownAddressIsAnOpenFailure) {
  TcpStream malformed("tcp://host:99999");
  EXPECT_EQ(errorKindOf([&] { malformed.open(); }), TransportErrorKind::kOpenFailed);
  TcpStream unknown("tcp://no-such-host.invalid:4001");  // .invalid never resolves (RFC 6761)
  EXPECT_EQ(errorKindOf([&] { unknown.open(); }), TransportErrorKind::kOpenFailed);
  EXPECT_FALSE(unknown.isOpen());
}

TEST_F(ConnectedTcpStream, WakeReadEndsABlockedRead) {
  ASSERT_TRUE(stream.wakeable());
  std::atomic<bool> returned{false};
  std::size_t got = 1;
  std::thread reader([&] {
    uint8_t buffer[8];
    got = stream.read(buffer, sizeof(buffer), 60000);  // far longer than the wait below
    returned = true;
  });
  stream.wakeRead();
  EXPECT_TRUE(waitFor([&] { return returned.load(); }, kWaitSeconds))
      << "the read sleeps on though it was woken";
  reader.join();
  EXPECT_EQ(got, 0u);
}

// --- SerialLink over TCP ---------------------------------------------------------------------

class CountingListener : public core::LinkListener {
 public:
  void onLinkUp() override { ++ups; }
  void onLinkDown() override { ++downs; }
  void onFrame(protocol::FrameFamily, const uint8_t*, std::size_t,
               core::Clock::time_point) override {
    ++frames;
  }
  std::atomic<int> ups{0}, downs{0}, frames{0};
};

TEST(SerialLinkOverTcp, ReconnectsWhenTheServerDropsTheConnection) {
  LoopbackServer server;
  core::SerialLinkOptions options;
  options.path = server.url();
  options.reconnect_interval = 0.05;
  options.framer = test_support::driverFramer({"base"}, 2);
  core::SerialLink link(options);  // the default factory: a tcp:// path is a TcpStream
  CountingListener listener;
  link.addListener(&listener);
  link.start();
  ASSERT_TRUE(server.accept());
  ASSERT_TRUE(link.waitConnected(std::chrono::milliseconds(kPatientTimeoutMs)));
  server.send(golden::base::kBattery87ReplySeq0);
  ASSERT_TRUE(waitFor([&] { return listener.frames == 1; }, kWaitSeconds));
  ASSERT_TRUE(link.write(golden::base::kResetSeq2));
  EXPECT_EQ(server.receive(golden::base::kResetSeq2.size()), golden::base::kResetSeq2);

  server.closeClient();  // the server's line went away
  ASSERT_TRUE(waitFor([&] { return listener.downs == 1; }, kWaitSeconds));
  EXPECT_FALSE(link.write(golden::base::kResetSeq2)) << "nothing is written while down";

  ASSERT_TRUE(server.accept()) << "the link did not connect again";
  ASSERT_TRUE(waitFor([&] { return link.connected(); }, kWaitSeconds));
  EXPECT_EQ(listener.ups, 2);
  server.send(golden::base::kBattery87ReplySeq0);
  EXPECT_TRUE(waitFor([&] { return listener.frames == 2; }, kWaitSeconds));
  EXPECT_EQ(link.stats().connects, 2u);
  link.stop();
}

}  // namespace
}  // namespace serial_robot_driver::transport
