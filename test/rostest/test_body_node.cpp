// driver_node's servo controller board end to end (body_node.test):
//  - the test plays the board on a pty: it writes telemetry bytes (hand-written from
//    docs/protocols.md 2b) and checks joint_states / imu/data / foot_pressure / telemetry, and it
//    reads the sync-write bytes (docs/protocols.md 2a) a joint_commands message produces;
//  - a second driver_node in namespace "sim" runs closed-loop with robot_sim;
//  - launch/record.launch records that namespace and `rosbag info` must list every topic.
//
// Counting without timing assumptions: every batch of frames ends with a sentinel frame, and a
// topic delivers in order, so "messages before the sentinel" is exact.
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

namespace {

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
const Bytes kGolden = {0x12, 0x34, 0x20, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB,
                       0x00, 0x01, 0xFF, 0xFF, 0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                       0x64, 0x00, 0x00, 0x00, 0x00, 0xC0, 0x00, 0x93, 0x1F, 0x2F};
// Sentinel: positions 256, 512, speeds 0, accel x = 0x0300, rest 0. SUM = 20+01+02+03 = 0x26.
const Bytes kSentinel = {0x12, 0x34, 0x20, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
                         0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                         0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x26, 0x1F, 0x2F};
// With the foot block (LEN = 40 + 8 = 0x30): the golden servo block, IMU all 0, foot bytes
// 01 .. 10 (little-endian: 0x0201, 0x0403, ..., 0x100F). SUM = 30 + 528 (servos) + 136 -> 0xC8.
const Bytes kFoot = {0x12, 0x34, 0x30, 0x08, 0x00, 0x00, 0x0A, 0x04, 0x00, 0xFF, 0xFB, 0x00,
                     0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                     0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07,
                     0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x10, 0xC8, 0x1F, 0x2F};
// Foot sentinel: positions 768, 1024, IMU 0, foot[0] = FF FF, rest 0. SUM = 30+03+04+FF+FF = 0x35.
const Bytes kFootSentinel = {
    0x12, 0x34, 0x30, 0x03, 0x00, 0x00, 0x00, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xFF, 0xFF, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x35, 0x1F, 0x2F};

// Sync pair, written only by Board::sync() so that no test frame can be mistaken for it.
// kSyncFoot: positions 1280, 1536, IMU 0, foot[0] = EE EE. SUM = 30+05+06+EE+EE = 0x17.
const Bytes kSyncFoot = {0x12, 0x34, 0x30, 0x05, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00, 0x00,
                         0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                         0x00, 0x00, 0x00, 0x00, 0x00, 0xEE, 0xEE, 0x00, 0x00, 0x00, 0x00, 0x00,
                         0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x17, 0x1F, 0x2F};
// kSync: positions 1792, 2048, accel x = 0x0500, rest 0. SUM = 20+07+08+05 = 0x34.
const Bytes kSync = {0x12, 0x34, 0x20, 0x07, 0x00, 0x00, 0x00, 0x08, 0x00, 0x00, 0x00,
                     0x05, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                     0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x34, 0x1F, 0x2F};

// joint_states of the sentinel: hip = (256 - 2048) ticks, knee (direction -1) = -(512 - 2048).
bool isSentinel(const JointState& m) {
  return m.position.size() == 2 && std::abs(m.position[0] - (-1792 * kRadPerTick)) < 1e-9 &&
         std::abs(m.position[1] - 1536 * kRadPerTick) < 1e-9;
}
bool isSentinel(const Imu& m) { return m.linear_acceleration.x == 384.0; }  // 0x300 * 0.5
bool isSentinel(const Telemetry& m) {
  return m.positions == std::vector<uint16_t>{256, 512} && !m.has_foot;
}
bool isSync(const JointState& m) {
  return m.position.size() == 2 && std::abs(m.position[0] - (-256 * kRadPerTick)) < 1e-9 &&
         std::abs(m.position[1]) < 1e-9;
}
bool isSync(const Imu& m) { return m.linear_acceleration.x == 640.0; }  // 0x500 * 0.5
bool isSync(const Telemetry& m) { return m.positions == std::vector<uint16_t>{1792, 2048}; }
bool isSync(const FootPressure& m) { return m.pressure[0] == 0xEEEE; }
bool isFootSentinel(const FootPressure& m) { return m.pressure[0] == 0xFFFF; }
bool isFootSentinel(const Telemetry& m) {
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

Board* g_board = nullptr;
std::string g_sim_ns;

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
      board.connect_failed = false;
    }
    ASSERT_TRUE(board.sync()) << "sentinel frames did not come back on every topic";
  }

  Board& board() { return *g_board; }
};

TEST_F(BodyNode, GoldenFrameGivesExactJointStateImuAndTelemetry) {
  const ros::Time before = ros::Time::now();
  board().write(kGolden);
  board().write(kSentinel);
  const auto joints = board().joints.waitFor([](const JointState& m) { return isSentinel(m); });
  const auto imu = board().imu.waitFor([](const Imu& m) { return isSentinel(m); });
  const auto telemetry =
      board().telemetry.waitFor([](const Telemetry& m) { return isSentinel(m); });
  const ros::Time after = ros::Time::now();
  ASSERT_TRUE(joints && imu && telemetry);
  ASSERT_EQ(joints->size(), 1u);
  ASSERT_EQ(imu->size(), 1u);
  ASSERT_EQ(telemetry->size(), 1u);

  // Joints: hip = 2048 - 2048 = 0; knee (direction -1) = -(1024 - 2048) ticks = pi/2;
  // no velocity: its scale is unknown (velocity_scale 0), so it is left empty, not guessed.
  const JointState& js = joints->front();
  EXPECT_EQ(js.name, (std::vector<std::string>{"hip", "knee"}));
  ASSERT_EQ(js.position.size(), 2u);
  EXPECT_TRUE(js.velocity.empty());
  EXPECT_NEAR(js.position[0], 0.0, 1e-12);
  EXPECT_NEAR(js.position[1], M_PI / 2, 1e-12);
  // Stamped with the arrival of the frame's last byte: after we wrote it, before we got it.
  EXPECT_GE(js.header.stamp.toSec(), before.toSec() - 1e-3);
  EXPECT_LE(js.header.stamp, after);

  // IMU: accel_scale 0.5, gyro_scale 0.25, default angle_scale: yaw -16384 LSB = -90 deg.
  const Imu& m = imu->front();
  EXPECT_EQ(m.header.frame_id, "imu_test");
  EXPECT_EQ(m.header.stamp, js.header.stamp);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.x, 0.5);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.y, -0.5);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.z, 8192.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.x, 0.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.y, 0.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.z, 25.0);
  EXPECT_NEAR(m.orientation.x, 0.0, 1e-9);
  EXPECT_NEAR(m.orientation.y, 0.0, 1e-9);
  EXPECT_NEAR(std::abs(m.orientation.z), std::sqrt(0.5), 1e-5);
  EXPECT_NEAR(std::abs(m.orientation.w), std::sqrt(0.5), 1e-5);
  EXPECT_LT(m.orientation.z * m.orientation.w, 0.0);  // negative yaw
  EXPECT_GT(m.orientation_covariance[0], 0.0);
  EXPECT_EQ(m.orientation_covariance[1], 0.0);

  // Telemetry: the raw frame.
  const Telemetry& t = telemetry->front();
  EXPECT_EQ(t.header.stamp, js.header.stamp);
  EXPECT_EQ(t.servo_ids, (std::vector<uint8_t>{2, 3}));
  EXPECT_EQ(t.positions, (std::vector<uint16_t>{2048, 1024}));
  EXPECT_EQ(t.speeds, (std::vector<int16_t>{10, -5}));
  const boost::array<int16_t, 9> raw_imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  EXPECT_EQ(t.imu, raw_imu);
  EXPECT_FALSE(t.has_foot);
  EXPECT_TRUE(t.foot.empty());
}

TEST_F(BodyNode, OnlyIntactFramesArePublished) {
  const Bytes junk = {0x00, 0xFF, 0x12, 0x00, 0x34, 0x1F, 0x2F, 0x12};
  const Bytes bad_sum = withByte(kGolden, 29, 0x94);
  const Bytes bad_tail = withByte(kGolden, 31, 0x2E);
  const Bytes truncated(kGolden.begin(), kGolden.begin() + 10);
  const Bytes bad_len = withByte(kGolden, 2, 0x24);  // LEN of 3 servos: impossible for N = 2
  const std::vector<Bytes> stream = {junk,    kGolden, bad_sum, kGolden, bad_tail, truncated,
                                     kGolden, bad_len, junk,    kGolden, kSentinel};
  for (const Bytes& chunk : stream) board().write(chunk);

  const auto joints = board().joints.waitFor([](const JointState& m) { return isSentinel(m); });
  const auto telemetry =
      board().telemetry.waitFor([](const Telemetry& m) { return isSentinel(m); });
  ASSERT_TRUE(joints && telemetry);
  EXPECT_EQ(joints->size(), 4u);
  EXPECT_EQ(telemetry->size(), 4u);
  for (const JointState& js : *joints) {
    ASSERT_EQ(js.position.size(), 2u);
    EXPECT_NEAR(js.position[0], 0.0, 1e-12);
    EXPECT_NEAR(js.position[1], M_PI / 2, 1e-12);
  }
}

TEST_F(BodyNode, ByteByByteDeliveryPublishesEveryFrame) {
  for (const Bytes* frame : {&kGolden, &kFoot, &kGolden, &kSentinel}) {
    for (uint8_t byte : *frame) {
      board().write(Bytes{byte});
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  }
  const auto joints = board().joints.waitFor([](const JointState& m) { return isSentinel(m); });
  ASSERT_TRUE(joints);
  EXPECT_EQ(joints->size(), 3u);
}

TEST_F(BodyNode, FootPressureOnlyForFramesWithTheFootBlock) {
  for (const Bytes* frame : {&kGolden, &kFoot, &kGolden, &kFoot, &kFootSentinel}) {
    board().write(*frame);
  }
  const auto foot = board().foot.waitFor([](const FootPressure& m) { return isFootSentinel(m); });
  const auto telemetry =
      board().telemetry.waitFor([](const Telemetry& m) { return isFootSentinel(m); });
  ASSERT_TRUE(foot && telemetry);
  ASSERT_EQ(foot->size(), 2u);
  const boost::array<uint16_t, 8> expected = {0x0201, 0x0403, 0x0605, 0x0807,
                                              0x0A09, 0x0C0B, 0x0E0D, 0x100F};
  EXPECT_EQ((*foot)[0].pressure, expected);
  EXPECT_EQ((*foot)[1].pressure, expected);

  ASSERT_EQ(telemetry->size(), 4u);
  std::vector<bool> has_foot;
  for (const Telemetry& t : *telemetry) has_foot.push_back(t.has_foot != 0);
  EXPECT_EQ(has_foot, (std::vector<bool>{false, true, false, true}));
  EXPECT_TRUE((*telemetry)[0].foot.empty());
  EXPECT_EQ((*telemetry)[1].foot, (std::vector<uint16_t>{0x0201, 0x0403, 0x0605, 0x0807, 0x0A09,
                                                         0x0C0B, 0x0E0D, 0x100F}));
  // Each foot_pressure message belongs to its frame: the same stamp as that frame's telemetry.
  EXPECT_EQ((*foot)[0].header.stamp, (*telemetry)[1].header.stamp);
  EXPECT_EQ((*foot)[1].header.stamp, (*telemetry)[3].header.stamp);
}

JointState command(const std::vector<std::string>& names, const std::vector<double>& positions) {
  JointState msg;
  msg.header.stamp = ros::Time::now();
  msg.name = names;
  msg.position = positions;
  return msg;
}

TEST_F(BodyNode, JointCommandsBecomeExactSyncWriteBytes) {
  ASSERT_TRUE(waitFor([&] { return board().joint_commands.getNumSubscribers() > 0; }, 30.0));
  board().drainInput();

  // Rejected commands write nothing: the first bytes on the wire belong to the valid one.
  board().joint_commands.publish(command({"hip", "elbow"}, {0.0, 0.0}));
  board().joint_commands.publish(command({"hip", "knee"}, {0.0}));
  board().joint_commands.publish(command({"hip", "knee"}, {0.0, std::nan("")}));
  // hip 0 rad -> 2048; knee pi/2 with direction -1 -> 2048 - 1024 = 1024 (docs/protocols.md 2a).
  board().joint_commands.publish(command({"hip", "knee"}, {0.0, M_PI / 2}));
  const Bytes& golden = golden::body::kSyncWrite2And3;
  EXPECT_EQ(board().read(golden.size()), golden);

  // Only knee, to -pi/2 -> 3072 = 00 0C; hip is sent again at 2048. CRC worked out by hand.
  board().joint_commands.publish(command({"knee"}, {-M_PI / 2}));
  const Bytes partial = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                         0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x0C, 0x4A, 0xE8};
  EXPECT_EQ(board().read(partial.size()), partial);
}

std::optional<std::string> value(const diagnostic_msgs::DiagnosticStatus& status,
                                 const std::string& key) {
  for (const auto& entry : status.values) {
    if (entry.key == key) return entry.value;
  }
  return std::nullopt;
}

TEST_F(BodyNode, DiagnosticsCountFramesAndRejectedCommands) {
  ros::NodeHandle nh;
  Inbox<diagnostic_msgs::DiagnosticArray> diagnostics;
  ros::Subscriber sub = subscribe(nh, "/diagnostics", &diagnostics);
  ASSERT_TRUE(waitFor([&] { return board().joint_commands.getNumSubscribers() > 0; }, 30.0));
  board().joint_commands.publish(command({"elbow"}, {0.0}));

  // The updater runs once a second; wait for a report that has seen both.
  std::optional<diagnostic_msgs::DiagnosticStatus> body;
  const auto counted = [&](const diagnostic_msgs::DiagnosticArray& array) {
    for (const auto& status : array.status) {
      if (status.name != "driver_node: body") continue;
      const auto frames = value(status, "frames decoded");
      const auto rejected = value(status, "commands rejected");
      if (frames && rejected && std::stoul(*frames) > 0 && std::stoul(*rejected) > 0) {
        body = status;
        return true;
      }
    }
    return false;
  };
  ASSERT_TRUE(diagnostics.waitFor(counted, 30.0)) << "no body status counting frames and rejects";
  EXPECT_EQ(body->hardware_id, value(*body, "port").value_or("(no port key)"));  // names the port
  EXPECT_FALSE(body->hardware_id.empty());
  EXPECT_EQ(value(*body, "connected"), std::optional<std::string>("True"));
  EXPECT_TRUE(value(*body, "decode errors").has_value());
  EXPECT_TRUE(value(*body, "commands sent").has_value());
  EXPECT_TRUE(value(*body, "Events since startup").has_value());  // the telemetry FrequencyStatus
}

// --- closed loop with robot_sim, and record.launch -----------------------------------------------

TEST(BodyNodeSim, JointCommandsMoveTheSimulatedServos) {
  ros::NodeHandle nh(g_sim_ns);
  Inbox<JointState> joints;
  Inbox<Imu> imu;
  ros::Subscriber joints_sub = subscribe(nh, "joint_states", &joints);
  ros::Subscriber imu_sub = subscribe(nh, "imu/data", &imu);
  ros::Publisher commands = nh.advertise<JointState>("joint_commands", 10);
  ASSERT_TRUE(joints.waitFor([](const JointState&) { return true; }, 60.0))
      << "no joint_states from the driver attached to robot_sim";
  ASSERT_TRUE(waitFor([&] { return commands.getNumSubscribers() > 0; }, 30.0));

  const double hip = 0.5, knee = -0.25;
  commands.publish(command({"hip", "knee"}, {hip, knee}));
  const auto reached = [&](const JointState& m) {
    return m.position.size() == 2 && std::abs(m.position[0] - hip) <= kRadPerTick &&
           std::abs(m.position[1] - knee) <= kRadPerTick;
  };
  EXPECT_TRUE(joints.waitFor(reached, 30.0)) << "the simulated servos never reached the targets";

  // The simulator's IMU sees 1 g on z at 16 g full scale: the default scales give 9.81 m/s^2.
  const auto any_imu = imu.waitFor([](const Imu&) { return true; }, 10.0);
  ASSERT_TRUE(any_imu);
  const std::vector<Imu> received = imu.snapshot();
  ASSERT_FALSE(received.empty());
  EXPECT_NEAR(received.back().linear_acceleration.z, 9.80665, 0.05);
}

bool recorderSubscribed(const std::string& topic) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false)) return false;
  XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i) {
    if (static_cast<std::string>(subscribers[i][0]) != topic) continue;
    for (int j = 0; j < subscribers[i][1].size(); ++j) {
      if (static_cast<std::string>(subscribers[i][1][j]).find("record") != std::string::npos) {
        return true;
      }
    }
  }
  return false;
}

std::string runAndCapture(const std::string& command) {
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return output;
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  pclose(pipe);
  return output;
}

TEST(BodyNodeSim, RecordLaunchRecordsEveryTopic) {
  char dir_template[] = "/tmp/srd_body_record_XXXXXX";
  ASSERT_NE(mkdtemp(dir_template), nullptr);
  const std::string dir = dir_template;
  const std::string ns = g_sim_ns;

  // roslaunch record.launch against this test's master, as a child we stop with SIGINT (Ctrl-C).
  test_support::ChildProcess launch(
      "roslaunch", {"serial_robot_driver", "record.launch", "bag:=" + dir + "/test", "ns:=" + ns},
      {"ROS_MASTER_URI=" + ros::master::getURI()});
  ASSERT_TRUE(launch.started()) << "could not start roslaunch";

  const std::string prefix = "/" + ns + "/";
  ros::NodeHandle nh(ns);
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  ros::Publisher joint_commands = nh.advertise<JointState>("joint_commands", 10);
  const bool subscribed = waitFor(
      [&] {
        // Each input topic has the driver and the recorder as subscribers.
        return recorderSubscribed(prefix + "telemetry") && cmd_vel.getNumSubscribers() >= 2 &&
               joint_commands.getNumSubscribers() >= 2;
      },
      60.0);
  if (subscribed) {
    cmd_vel.publish(geometry_msgs::Twist());
    joint_commands.publish(command({"hip"}, {0.1}));
    // A few seconds: diagnostics and battery come at 1 Hz.
    ros::WallDuration(3.5).sleep();
  }
  launch.signal(SIGINT);
  const bool exited = launch.waitExit(60.0).has_value();  // if not, the destructor kills it
  ASSERT_TRUE(subscribed) << "rosbag record never subscribed; roslaunch said:\n" << launch.output();
  ASSERT_TRUE(exited) << "roslaunch did not stop on SIGINT";

  glob_t found;
  const std::string pattern = dir + "/test_*.bag";
  ASSERT_EQ(glob(pattern.c_str(), 0, nullptr, &found), 0) << "no bag matching " << pattern;
  ASSERT_EQ(found.gl_pathc, 1u);
  const std::string bag = found.gl_pathv[0];
  globfree(&found);
  const std::string info = runAndCapture("rosbag info " + bag + " 2>&1");
  for (const std::string& topic :
       {prefix + "joint_states", prefix + "imu/data", prefix + "foot_pressure",
        prefix + "telemetry", prefix + "wheel_command", prefix + "battery", prefix + "cmd_vel",
        prefix + "joint_commands", std::string("/diagnostics")}) {
    EXPECT_NE(info.find(topic + " "), std::string::npos) << topic << " missing from\n" << info;
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);  // kept for a look when something failed
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_body_node");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  std::string port = "/tmp/srd_test_body";
  private_nh.param("port", port, port);
  private_nh.param("sim_ns", g_sim_ns, std::string("sim"));

  Board board;
  // The pty first: the node keeps retrying its port until the symlink exists.
  serial_robot_driver::protocol::FramerConfig framer;
  framer.sync_write = true;
  board.device = std::make_unique<test_support::FakeDevice>(port, framer);
  board.device->plug();
  board.subscribers.push_back(subscribe(nh, "joint_states", &board.joints));
  board.subscribers.push_back(subscribe(nh, "imu/data", &board.imu));
  board.subscribers.push_back(subscribe(nh, "foot_pressure", &board.foot));
  board.subscribers.push_back(subscribe(nh, "telemetry", &board.telemetry));
  board.joint_commands = nh.advertise<JointState>("joint_commands", 10);
  g_board = &board;

  const int result = RUN_ALL_TESTS();
  g_board = nullptr;
  board.device->unplug();
  return result;
}
