// What the body_node.test tests share: telemetry and sync frames written out by hand from
// docs/protocols.md 2a/2b, topic inboxes, the board on a pty (Board) and the BodyNode fixture.
//
// Counting without timing assumptions: every batch of frames ends with a sentinel frame, and a
// topic delivers in order, so "messages before the sentinel" is exact.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Twist.h>
#include <glob.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <serial_robot_driver/FootPressure.h>
#include <serial_robot_driver/Telemetry.h>
#include <signal.h>
#include <stdlib.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
#include "support/ros_test_support.h"

namespace body_node_test {

using sensor_msgs::Imu;
using sensor_msgs::JointState;
using serial_robot_driver::FootPressure;
using serial_robot_driver::Telemetry;
using test_support::Bytes;
using test_support::waitFor;
using test_support::withByte;

constexpr double kRadPerTick = 2.0 * M_PI / 4096.0;

// --- frames, written out by hand from docs/protocols.md, section 2b (N = 2 servos: ids 2, 3) -----

// The golden vector: positions 2048, 1024; speeds 10, -5; IMU 1, -1, 16384, 0, 0, 100, 0, 0,
// -16384. SUM = 0x93.
inline const Bytes kGolden = {0x12, 0x34, 0x20, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB,
                              0x00, 0x01, 0xFF, 0xFF, 0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                              0x64, 0x00, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x93, 0x1F, 0x2F};
// Sentinel: positions 256, 512, speeds 0, accel x = 0x0300, rest 0. SUM = 20+01+02+03 = 0x26.
inline const Bytes kSentinel = {0x12, 0x34, 0x20, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
                                0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x26, 0x1F, 0x2F};
// With the foot block (LEN = 40 + 8 = 0x30): the golden servo block, IMU all 0, foot bytes
// 01 .. 10 (little-endian: 0x0201, 0x0403, ..., 0x100F). SUM = 30 + 528 (servos) + 136 -> 0xC8.
inline const Bytes kFoot = {0x12, 0x34, 0x30, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB, 0x00,
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07,
                            0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x10, 0xC8, 0x1F, 0x2F};
// Foot sentinel: positions 768, 1024, IMU 0, foot[0] = FF FF, rest 0. SUM = 30+03+04+FF+FF = 0x35.
inline const Bytes kFootSentinel = {
    0x12, 0x34, 0x30, 0x03, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xFF, 0xFF, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x35, 0x1F, 0x2F};

// Sync pair, written only by Board::sync() so that no test frame can be mistaken for it.
// kSyncFoot: positions 1280, 1536, IMU 0, foot[0] = EE EE. SUM = 30+05+06+EE+EE = 0x17.
inline const Bytes kSyncFoot = {
    0x12, 0x34, 0x30, 0x05, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xEE, 0xEE, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x17, 0x1F, 0x2F};
// kSync: positions 1792, 2048, accel x = 0x0500, rest 0. SUM = 20+07+08+05 = 0x34.
inline const Bytes kSync = {0x12, 0x34, 0x20, 0x07, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00,
                            0x05, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                            0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x34, 0x1F, 0x2F};

// joint_states of the sentinel: hip = (256 - 2048) ticks, knee (direction -1) = -(512 - 2048).
inline bool isSentinel(const JointState& m) {
  return m.position.size() == 2 && std::abs(m.position[0] - (-1792 * kRadPerTick)) < 1e-9 &&
         std::abs(m.position[1] - 1536 * kRadPerTick) < 1e-9;
}
inline bool isSentinel(const Imu& m) { return m.linear_acceleration.x == 384.0; }  // 0x300 * 0.5
inline bool isSentinel(const Telemetry& m) {
  return m.positions == std::vector<uint16_t>{256, 512} && !m.has_foot;
}
inline bool isSync(const JointState& m) {
  return m.position.size() == 2 && std::abs(m.position[0] - (-256 * kRadPerTick)) < 1e-9 &&
         std::abs(m.position[1]) < 1e-9;
}
inline bool isSync(const Imu& m) { return m.linear_acceleration.x == 640.0; }  // 0x500 * 0.5
inline bool isSync(const Telemetry& m) { return m.positions == std::vector<uint16_t>{1792, 2048}; }
inline bool isSync(const FootPressure& m) { return m.pressure[0] == 0xEEEE; }
inline bool isFootSentinel(const FootPressure& m) { return m.pressure[0] == 0xFFFF; }
inline bool isFootSentinel(const Telemetry& m) {
  return m.has_foot && m.foot.size() == 8 && m.foot[0] == 0xFFFF;
}

// --- message collection ------------------------------------------------------------------------

template <typename M>
class Inbox {
 public:
  void push(const M& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(msg);
    cv_.notify_all();
  }
  /// Waits until some message satisfies `pred`; returns the messages before the first such one.
  std::optional<std::vector<M>> waitFor(const std::function<bool(const M&)>& pred,
                                        double timeout_s = 15.0) {
    std::unique_lock<std::mutex> lock(mutex_);
    std::optional<std::vector<M>> before;
    cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
      for (std::size_t i = 0; i < messages_.size(); ++i) {
        if (pred(messages_[i])) {
          before.emplace(messages_.begin(), messages_.begin() + i);
          return true;
        }
      }
      return false;
    });
    return before;
  }
  std::vector<M> snapshot() {
    std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.clear();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<M> messages_;
};

template <typename M>
ros::Subscriber subscribe(ros::NodeHandle& nh, const std::string& topic, Inbox<M>* inbox) {
  // tcpNoDelay: the driver publishes each frame at once; Nagle would only add latency here.
  return nh.subscribe<M>(
      topic, 1000, [inbox](const boost::shared_ptr<const M>& msg) { inbox->push(*msg); },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
}

// --- the pty driver_node
// ---------------------------------------------------------------------------

struct Board {
  std::unique_ptr<test_support::FakeDevice> device;  ///< the board: records what the node writes
  Inbox<JointState> joints;
  Inbox<Imu> imu;
  Inbox<FootPressure> foot;
  Inbox<Telemetry> telemetry;
  std::vector<ros::Subscriber> subscribers;
  ros::Publisher joint_commands;
  bool connected = false;
  bool connect_failed = false;

  // The subscribers' callbacks write to the inboxes on the spinner thread: end them (shutdown()
  // waits for a running one) before the inboxes die.
  ~Board() {
    for (ros::Subscriber& subscriber : subscribers) subscriber.shutdown();
  }

  void write(const Bytes& bytes) { device->write(bytes); }

  void clear() {
    joints.clear();
    imu.clear();
    foot.clear();
    telemetry.clear();
  }

  /// Flushes every topic: after this, no message of an earlier frame is still on its way (each
  /// topic is in order, and the sync frames come after everything written before).
  bool sync() {
    clear();
    write(kSyncFoot);
    write(kSync);
    const bool ok = foot.waitFor([](const FootPressure& m) { return isSync(m); }) &&
                    joints.waitFor([](const JointState& m) { return isSync(m); }) &&
                    imu.waitFor([](const Imu& m) { return isSync(m); }) &&
                    telemetry.waitFor([](const Telemetry& m) { return isSync(m); });
    clear();
    return ok;
  }

  /// Reads exactly `count` bytes the driver wrote, or what came within the timeout.
  Bytes read(std::size_t count, double timeout_s = 10.0) {
    return device->takeBytes(count, timeout_s);
  }

  /// Discards what the driver wrote so far, once 50 ms pass without a new byte.
  void drainInput() {
    std::size_t received = device->mark();
    do {
      received = device->mark();
      test_support::sleepSeconds(0.05);
    } while (device->mark() != received);
    device->skipReceived();
  }
};

inline Board* g_board = nullptr;
inline std::string g_sim_ns;

class BodyNode : public testing::Test {
 protected:
  void SetUp() override {
    Board& board = *g_board;
    ASSERT_FALSE(board.connect_failed) << "driver_node did not come up (see the first test)";
    if (!board.connected) {
      board.connect_failed = true;  // until proven otherwise: later tests then fail fast
      // The node opens the pty within reconnect_interval of starting; keep offering a sentinel
      // until one comes back as joint_states.
      ASSERT_TRUE(waitFor([&] { return board.subscribers[0].getNumPublishers() > 0; }, 60.0))
          << "driver_node never advertised joint_states";
      for (int attempt = 0; attempt < 100 && !board.connected; ++attempt) {
        board.write(kSentinel);
        board.connected =
            board.joints.waitFor([](const JointState& m) { return isSentinel(m); }, 0.3)
                .has_value();
      }
      ASSERT_TRUE(board.connected) << "no joint_states for telemetry written to the pty";
      // Each topic's subscription connects on its own, and the node builds no message for a topic
      // with no subscriber it counts yet: the sync below needs all four counted.
      for (const ros::Subscriber& subscriber : board.subscribers) {
        ASSERT_TRUE(waitFor(
            [&] {
              return test_support::nodeCountsSubscriber("/driver_node", subscriber.getTopic());
            },
            20.0))
            << "/driver_node never counted the subscriber of " << subscriber.getTopic();
      }
      board.connect_failed = false;
    }
    ASSERT_TRUE(board.sync()) << "sentinel frames did not come back on every topic";
  }

  Board& board() { return *g_board; }
};

inline JointState command(const std::vector<std::string>& names,
                          const std::vector<double>& positions) {
  JointState msg;
  msg.header.stamp = ros::Time::now();
  msg.name = names;
  msg.position = positions;
  return msg;
}

}  // namespace body_node_test
