// WireCapture (serial_raw) against a subscriber that stops reading: memory stays bounded (the
// capture's queue and what roscpp holds never pass their limits), the capture's own drop counter
// reacts in its diagnostic status, and the count is true: once the subscriber reads again, it
// receives exactly the chunks the capture says it published, in order, and the missing ones are
// exactly the ones it says it dropped (roscpp discarded none). An in-process subscriber sees the
// same stream.
//
// The slow subscriber is a raw TCPROS connection made by hand (requestTopic over XML-RPC, then the
// connection header) with a tiny receive buffer, so that the kernel's buffers fill after a few
// chunks and roscpp's outgoing queue is what grows. Nothing here asserts timing: each step waits
// for its condition with a generous timeout.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <ros/header.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <ros/serialization.h>
#include <ros/topic_manager.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/ros/wire_capture.h"
#include "support/ros_test_support.h"

namespace {

using serial_robot_driver::SerialChunk;
using serial_robot_driver::ros_layer::DriverParams;
using serial_robot_driver::ros_layer::WireCapture;
using serial_robot_driver::ros_layer::WireCaptureLimits;
using serial_robot_driver::ros_layer::WireCaptureStats;
using test_support::waitFor;

constexpr double kTimeout = 60.0;  // s: generous, the machine is shared
constexpr std::size_t kChunkBytes = 8192;

/// A TCPROS subscriber of `topic` on this very node, made by hand so that it reads only when told.
class RawSubscriber {
 public:
  explicit RawSubscriber(const std::string& topic) {
    // Where this node serves the topic: its own XML-RPC API, as any subscriber asks.
    XmlRpc::XmlRpcValue request, response, payload;
    request[0] = ros::this_node::getName();
    request[1] = ros::this_node::getName();
    if (!ros::master::execute("lookupNode", request, response, payload, false)) return;
    std::string host;
    uint32_t port = 0;
    if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return;
    XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
    XmlRpc::XmlRpcValue topic_request, topic_response, protocols, tcpros;
    tcpros[0] = std::string("TCPROS");
    protocols[0] = tcpros;
    topic_request[0] = ros::this_node::getName();
    topic_request[1] = topic;
    topic_request[2] = protocols;
    if (!client.execute("requestTopic", topic_request, topic_response)) return;
    if (static_cast<int>(topic_response[0]) != 1) return;
    const std::string tcp_host = topic_response[2][1];
    const int tcp_port = topic_response[2][2];

    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    if (::getaddrinfo(tcp_host.c_str(), std::to_string(tcp_port).c_str(), &hints, &found) != 0) {
      return;
    }
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    // As small as the kernel allows (before connect, so the window is small from the start).
    const int small = 1024;
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
    timeval wait{0, 200000};  // reads come back every 0.2 s at most, to check the deadline
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &wait, sizeof(wait));
    const bool connected = ::connect(fd_, found->ai_addr, found->ai_addrlen) == 0;
    ::freeaddrinfo(found);
    if (!connected) return;

    ros::M_string fields;
    fields["callerid"] = ros::this_node::getName() + "_raw";
    fields["topic"] = topic;
    fields["md5sum"] = ros::message_traits::MD5Sum<SerialChunk>::value();
    fields["type"] = ros::message_traits::DataType<SerialChunk>::value();
    fields["tcp_nodelay"] = "1";
    boost::shared_array<uint8_t> header;
    uint32_t header_size = 0;
    ros::Header::write(fields, header, header_size);
    if (!writeAll(&header_size, 4) || !writeAll(header.get(), header_size)) return;
    // The publisher's answer: a header without "error".
    std::vector<uint8_t> answer;
    if (!readRecord(answer, ros::WallTime::now() + ros::WallDuration(kTimeout))) return;
    ros::Header parsed;
    std::string error;
    if (!parsed.parse(answer.data(), static_cast<uint32_t>(answer.size()), error)) return;
    if (parsed.getValue("error", error)) return;
    ok_ = true;
  }

  ~RawSubscriber() {
    if (fd_ >= 0) ::close(fd_);
  }

  bool ok() const { return ok_; }

  /// Reads one message; false when none began to arrive within `wait_s` (one that began is read
  /// to its end, by `deadline`, so the stream never loses its place).
  bool read(SerialChunk& chunk, double wait_s, ros::WallTime deadline) {
    pollfd readable{fd_, POLLIN, 0};
    if (::poll(&readable, 1, static_cast<int>(wait_s * 1000)) != 1) return false;
    std::vector<uint8_t> bytes;
    if (!readRecord(bytes, deadline)) return false;
    ros::serialization::IStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
    ros::serialization::deserialize(stream, chunk);
    return true;
  }

 private:
  bool writeAll(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const uint8_t*>(data);
    while (size > 0) {
      const ssize_t n = ::send(fd_, bytes, size, MSG_NOSIGNAL);
      if (n <= 0) return false;
      bytes += n;
      size -= static_cast<std::size_t>(n);
    }
    return true;
  }

  bool readAll(uint8_t* data, std::size_t size, ros::WallTime deadline) {
    while (size > 0) {
      const ssize_t n = ::recv(fd_, data, size, 0);
      if (n == 0) return false;  // closed
      if (n < 0) {
        if ((errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) &&
            ros::WallTime::now() < deadline) {
          continue;
        }
        return false;
      }
      data += n;
      size -= static_cast<std::size_t>(n);
    }
    return true;
  }

  /// A 4-byte little-endian length, then that many bytes (a header or a message).
  bool readRecord(std::vector<uint8_t>& record, ros::WallTime deadline) {
    uint8_t length[4];
    if (!readAll(length, 4, deadline)) return false;
    const uint32_t size = static_cast<uint32_t>(length[0]) | static_cast<uint32_t>(length[1]) << 8 |
                          static_cast<uint32_t>(length[2]) << 16 |
                          static_cast<uint32_t>(length[3]) << 24;
    record.resize(size);
    return readAll(record.data(), size, deadline);
  }

  int fd_ = -1;
  bool ok_ = false;
};

uint64_t sequenceOf(const std::vector<uint8_t>& data) {
  uint64_t seq = 0;
  std::memcpy(&seq, data.data(), sizeof(seq));
  return seq;
}

TEST(WireCapture, AStalledSubscriberMakesTheCaptureDropAndCountWithBoundedMemory) {
  ros::NodeHandle nh("wire_capture_test");
  WireCaptureLimits limits;
  limits.max_queued = 100;
  limits.max_in_roscpp = 20;
  WireCapture capture(nh, DriverParams{}, limits);
  const std::string topic = nh.resolveName("serial_raw");

  // The in-process subscriber reads everything at once.
  std::mutex mutex;
  std::vector<uint64_t> in_process;
  ros::Subscriber fast =
      nh.subscribe<SerialChunk>("serial_raw", 100000, [&](const SerialChunk::ConstPtr& chunk) {
        std::lock_guard<std::mutex> lock(mutex);
        in_process.push_back(sequenceOf(chunk->data));
      });
  RawSubscriber slow(topic);
  ASSERT_TRUE(slow.ok()) << "no TCPROS connection to " << topic;
  ASSERT_TRUE(waitFor([&] { return ros::TopicManager::instance()->getNumSubscribers(topic) == 2; },
                      kTimeout));

  // Chunks until the slow subscriber's kernel buffers and then roscpp's share are full, the
  // capture's queue fills and drops: the publishing was held back, not discarded inside roscpp.
  const std::string port = "/dev/ttyTEST";
  std::vector<uint8_t> bytes(kChunkBytes, 0x5A);
  uint64_t fed = 0;
  bool held_back = false;
  WireCaptureStats stats;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
  while (ros::WallTime::now() < deadline) {
    std::memcpy(bytes.data(), &fed, sizeof(fed));
    capture.onChunk({port, false, bytes.data(), bytes.size(), std::chrono::steady_clock::now()});
    ++fed;
    stats = capture.stats();
    ASSERT_LE(stats.queued, limits.max_queued);
    ASSERT_LE(stats.in_roscpp, limits.max_in_roscpp);
    held_back = held_back || stats.in_roscpp == limits.max_in_roscpp;
    if (held_back && stats.dropped >= 10) break;
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // let the publisher run
  }
  ASSERT_TRUE(held_back) << "roscpp never held max_in_roscpp chunks; fed " << fed;
  ASSERT_GE(stats.dropped, 10u) << "fed " << fed;

  // The diagnostic status says so.
  diagnostic_updater::DiagnosticStatusWrapper status;
  capture.diagnose(status);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN) << status.message;
  std::map<std::string, std::string> values;
  for (const auto& kv : status.values) values[kv.key] = kv.value;
  EXPECT_GE(std::stoull(values["chunks dropped"]), 10u);
  EXPECT_LE(std::stoull(values["chunks queued"]), limits.max_queued);
  EXPECT_LE(std::stoull(values["chunks held by roscpp"]), limits.max_in_roscpp);

  // The slow subscriber reads again: it gets every published chunk, in order, and nothing else.
  std::vector<uint64_t> received;
  const ros::WallTime drain_deadline = ros::WallTime::now() + ros::WallDuration(kTimeout);
  while (ros::WallTime::now() < drain_deadline) {
    stats = capture.stats();
    if (stats.queued == 0 && received.size() == stats.chunks) break;
    SerialChunk chunk;
    if (slow.read(chunk, 0.2, drain_deadline)) {
      received.push_back(sequenceOf(chunk.data));
    }
  }
  stats = capture.stats();
  EXPECT_EQ(stats.queued, 0u);
  EXPECT_EQ(stats.chunks + stats.dropped, fed) << "every chunk is published or counted as dropped";
  ASSERT_EQ(received.size(), stats.chunks) << "roscpp discarded chunks the capture did not count";
  for (std::size_t i = 1; i < received.size(); ++i) ASSERT_LT(received[i - 1], received[i]);
  ASSERT_TRUE(waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return in_process.size() >= stats.chunks;
      },
      kTimeout));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(in_process, received) << "every subscriber sees the same stream";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_wire_capture");
  return RUN_ALL_TESTS();
}
