// What the base_node.test tests share: frames written out by hand from docs/protocols.md,
// section 1, FakeBase (the base on a pty, split into frames with the project's StreamFramer), the
// node's topics and services (RosSide), a cmd_vel streamer and BaseNodeTest, which puts every test
// on a fresh pty so the node reconnects and no state leaks between tests.
#pragma once

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/BatteryState.h>
#include <signal.h>
#include <std_srvs/Trigger.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
#include "support/ros_test_support.h"

namespace base_node_test {

namespace protocol = serial_robot_driver::protocol;
using test_support::Bytes;
using test_support::ChildProcess;
using test_support::Clock;
using test_support::waitFor;

// --- numbers from docs/protocols.md, section 1 and the node's defaults ---------------------------
// 1600 ticks/rev, 0.25 m wheels, 50 Hz PID: 1600 / (0.25 pi) / 50 ticks per period at 1 m/s.
constexpr double kTicksAt1Mps = 40.7437;
constexpr uint8_t kMsgWheelSpeed = 0x01;
constexpr uint8_t kMsgBattery = 0x02;
constexpr uint8_t kMsgReset = 0x05;
constexpr uint8_t kMsgClearEncoders = 0x06;

/// Appends the XOR of all bytes: computed here, independently of the codec under test.
inline Bytes withXor(Bytes frame) {
  uint8_t x = 0;
  for (uint8_t b : frame) x ^= b;
  frame.push_back(x);
  return frame;
}

inline Bytes resetFrame(uint8_t seq) { return withXor({0x55, 0xAA, 0x02, seq, 0x05, 0x00}); }
inline Bytes clearEncodersFrame(uint8_t seq) {
  return withXor({0x55, 0xAA, 0x02, seq, 0x06, 0x00});
}
inline Bytes batteryRequestFrame(uint8_t seq) {
  return withXor({0x55, 0xAA, 0x02, seq, 0x02, 0x00});
}
inline Bytes zeroSpeedFrame(uint8_t seq) {
  return withXor({0x55, 0xAA, 0x09, seq, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00});
}

// Base -> host frames, written out by hand (XOR included).
inline const Bytes& kTimeoutErrorFrame = golden::base::kErrorStatusSeq32;         // FF status
inline const Bytes& kBattery87PercentFrame = golden::base::kBattery87ReplySeq16;  // 0x57 = 87 %

// --- the fake base on a pty ----------------------------------------------------------------------

/// One frame the node wrote, as read from the pty.
struct SeenFrame {
  Bytes bytes;
  uint8_t seq = 0;
  uint8_t msg_id = 0;
  Clock::time_point arrival;

  bool isSpeed() const { return msg_id == kMsgWheelSpeed; }
  bool isReset() const { return msg_id == kMsgReset; }
  // Decoded here by hand (big-endian int16) rather than with the codec under test.
  int16_t left() const { return static_cast<int16_t>((bytes.at(5) << 8) | bytes.at(6)); }
  int16_t right() const { return static_cast<int16_t>((bytes.at(7) << 8) | bytes.at(8)); }
  bool isZeroSpeed() const { return isSpeed() && left() == 0 && right() == 0; }
};

/// Plays the AP1 base on a pty with a symlink at `path`: a FakeDevice (whose reader drains
/// everything the node writes, so its writes never stall) seen through the base frames of the
/// current session (since the last plug()).
class FakeBase {
 public:
  explicit FakeBase(std::string path) : device_(std::move(path), baseFramer()) { plug(); }

  /// Creates a new pty at the path (a fresh session: the frame list starts empty).
  void plug() { device_.plug(); }
  /// Closes the pty and removes the symlink: to the node this looks like an unplugged adapter.
  void unplug() { device_.unplug(); }

  void write(const Bytes& bytes) { device_.write(bytes); }

  std::vector<SeenFrame> frames() const {
    std::vector<SeenFrame> seen;
    for (const auto& frame : device_.frames()) {
      const auto decoded =
          serial_robot_driver::devices::base::decodeFrame(frame.bytes.data(), frame.bytes.size());
      if (frame.family != serial_robot_driver::devices::base::kFrames || !decoded) continue;
      seen.push_back(SeenFrame{frame.bytes, decoded->seq, decoded->msg_id, frame.arrival});
    }
    return seen;
  }
  std::size_t count() const { return frames().size(); }
  /// Waits until at least `n` frames of this session were read.
  bool waitForCount(std::size_t n, double timeout_s) const {
    return waitFor([&] { return count() >= n; }, timeout_s);
  }
  /// Waits until `pred` holds for the frames read so far.
  bool waitUntil(const std::function<bool(const std::vector<SeenFrame>&)>& pred,
                 double timeout_s) const {
    return waitFor([&] { return pred(frames()); }, timeout_s);
  }

  /// Bytes that were not part of a valid base frame (checksum errors, resyncs, bad lengths).
  uint64_t garbage() const {
    const protocol::FramerStats stats = device_.framerStats();
    const uint64_t undecodable = device_.frameCount() - count();
    return stats.checksum_errors + stats.bad_lengths + undecodable + stats.bytes_skipped;
  }
  Clock::time_point pluggedAt() const { return device_.pluggedAt(); }

 private:
  static protocol::FramerConfig baseFramer() {
    protocol::FramerConfig config;
    config.accept(serial_robot_driver::devices::base::kFrames);
    return config;
  }

  test_support::FakeDevice device_;
};

// Frame-list helpers ----------------------------------------------------------------------------

inline std::vector<SeenFrame> speedFramesFrom(const std::vector<SeenFrame>& frames,
                                              std::size_t from) {
  std::vector<SeenFrame> out;
  for (std::size_t i = from; i < frames.size(); ++i) {
    if (frames[i].isSpeed()) out.push_back(frames[i]);
  }
  return out;
}

inline std::optional<std::size_t> findFrom(const std::vector<SeenFrame>& frames, std::size_t from,
                                           const std::function<bool(const SeenFrame&)>& pred) {
  for (std::size_t i = from; i < frames.size(); ++i) {
    if (pred(frames[i])) return i;
  }
  return std::nullopt;
}

inline bool isZeroSpeedFrame(const SeenFrame& f) { return f.isZeroSpeed(); }

/// Index of the first speed frame at or after `from` that moves a wheel.
inline std::optional<std::size_t> firstMoving(const std::vector<SeenFrame>& frames,
                                              std::size_t from) {
  return findFrom(frames, from, [](const SeenFrame& f) { return f.isSpeed() && !f.isZeroSpeed(); });
}

/// Number of speed frames at or after `from`.
inline std::size_t speedCount(const std::vector<SeenFrame>& frames, std::size_t from) {
  std::size_t n = 0;
  for (std::size_t i = from; i < frames.size(); ++i) n += frames[i].isSpeed() ? 1 : 0;
  return n;
}

inline double meanLeft(const std::vector<SeenFrame>& speed) {
  double sum = 0;
  for (const auto& f : speed) sum += f.left();
  return speed.empty() ? 0.0 : sum / speed.size();
}
inline double meanRight(const std::vector<SeenFrame>& speed) {
  double sum = 0;
  for (const auto& f : speed) sum += f.right();
  return speed.empty() ? 0.0 : sum / speed.size();
}

// --- the ROS side --------------------------------------------------------------------------------

struct TimedWheelCommand {
  Clock::time_point received;
  serial_robot_driver::WheelCommand msg;
};

/// Subscriptions to the node under test, created once in main().
class RosSide {
 public:
  /// `node_name`: the driver's, whose "<node>: base" diagnostic status is watched.
  explicit RosSide(const std::string& node_name)
      : node_name_(ros::names::resolve(node_name)), diagnostics_(nh_, node_name) {
    cmd_vel_ = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
    wheel_sub_ = nh_.subscribe("wheel_command", 1000, &RosSide::onWheelCommand, this);
    battery_sub_ = nh_.subscribe("battery", 10, &RosSide::onBattery, this);
  }
  // The spinner thread keeps calling onWheelCommand/onBattery until the subscriptions end, and the
  // members below die before the subscribers would: shutdown() waits for a running callback.
  ~RosSide() {
    wheel_sub_.shutdown();
    battery_sub_.shutdown();
  }
  RosSide(const RosSide&) = delete;
  RosSide& operator=(const RosSide&) = delete;

  ros::NodeHandle& nh() { return nh_; }
  ros::Publisher& cmdVel() { return cmd_vel_; }

  std::vector<TimedWheelCommand> wheelCommands() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return wheel_commands_;
  }
  /// The WheelCommand with this seq received after `since`, if any.
  std::optional<serial_robot_driver::WheelCommand> wheelCommand(uint8_t seq,
                                                                Clock::time_point since) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& c : wheel_commands_) {
      if (c.received >= since && c.msg.seq == seq) return c.msg;
    }
    return std::nullopt;
  }
  bool waitWheelCommand(uint8_t seq, Clock::time_point since, double timeout_s) const {
    return waitFor([&] { return wheelCommand(seq, since).has_value(); }, timeout_s);
  }

  /// Waits until the node counts both subscriptions: it builds no message for one it does not.
  bool waitCountedByNode(double timeout_s) const {
    return waitFor(
        [&] {
          return test_support::nodeCountsSubscriber(node_name_, wheel_sub_.getTopic()) &&
                 test_support::nodeCountsSubscriber(node_name_, battery_sub_.getTopic());
        },
        timeout_s);
  }

  std::vector<sensor_msgs::BatteryState> battery() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return battery_;
  }

  /// The node's latest "<node>: base" diagnostic status.
  test_support::DiagnosticsWatch::Status baseDiagnostics() const {
    return diagnostics_.latest("base");
  }

 private:
  void onWheelCommand(const serial_robot_driver::WheelCommand::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    wheel_commands_.push_back({Clock::now(), *msg});
  }
  void onBattery(const sensor_msgs::BatteryState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    battery_.push_back(*msg);
  }

  std::string node_name_;
  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher cmd_vel_;
  ros::Subscriber wheel_sub_, battery_sub_;
  mutable std::mutex mutex_;
  std::vector<TimedWheelCommand> wheel_commands_;
  std::vector<sensor_msgs::BatteryState> battery_;
};

inline RosSide* g_ros = nullptr;
inline std::string g_port;         // the pty path driver_node was given
inline std::string g_driver_path;  // the driver_node executable, for the tests that start their own

/// Publishes a Twist at 20 Hz on its own thread, the way a teleop or navigation node does.
class CmdVelStreamer {
 public:
  explicit CmdVelStreamer(ros::Publisher publisher) : publisher_(std::move(publisher)) {
    thread_ = std::thread([this] { run(); });
  }
  ~CmdVelStreamer() { stop(true); }

  void set(double linear_x, double angular_z) {
    std::lock_guard<std::mutex> lock(mutex_);
    linear_x_ = linear_x;
    angular_z_ = angular_z;
    active_ = true;
  }
  /// Stops publishing; with `send_zero`, one last zero Twist first (so the next test starts still).
  void stop(bool send_zero) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_) return;
      stopping_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
    if (send_zero && ever_active_) publisher_.publish(geometry_msgs::Twist());
  }

 private:
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stopping_) {
      if (active_) {
        geometry_msgs::Twist twist;
        twist.linear.x = linear_x_;
        twist.angular.z = angular_z_;
        ever_active_ = true;
        lock.unlock();
        publisher_.publish(twist);
        lock.lock();
      }
      cv_.wait_for(lock, std::chrono::milliseconds(50), [this] { return stopping_; });
    }
  }

  ros::Publisher publisher_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool stopping_ = false;
  bool active_ = false;
  bool ever_active_ = false;
  double linear_x_ = 0, angular_z_ = 0;
  std::thread thread_;
};

// --- child processes (tests that need their own driver_node) -------------------------------------

/// Arguments for a base-only driver_node named `name` in namespace `ns` on `port`.
inline std::vector<std::string> driverArgs(const std::string& ns, const std::string& name,
                                           const std::string& port) {
  return {"__ns:=" + ns,
          "__name:=" + name,
          "_port:=" + port,
          "_reconnect_interval:=0.2",
          "_body/enabled:=false",
          "_servo_bus/enabled:=false",
          "_base/battery_poll_rate:=0.0"};
}

// --- the fixture ---------------------------------------------------------------------------------

class BaseNodeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_NE(g_ros, nullptr);
    // Before the port exists, so that every frame the node writes is reported on wheel_command
    // (the first test also waits here for the node to start).
    ASSERT_TRUE(g_ros->waitCountedByNode(20.0)) << "driver_node does not count the subscriptions";
    base_ = std::make_unique<FakeBase>(g_port);
    // Later tests wait here for the node's reconnect.
    ASSERT_TRUE(base_->waitForCount(2, 20.0)) << "driver_node never wrote to " << g_port;
  }

  void TearDown() override {
    if (streamer_) streamer_->stop(true);
    streamer_.reset();
    if (base_) {
      EXPECT_EQ(base_->garbage(), 0u) << "bytes outside valid base frames";
    }
    base_.reset();
  }

  CmdVelStreamer& streamer() {
    if (!streamer_) {
      EXPECT_TRUE(waitFor([] { return g_ros->cmdVel().getNumSubscribers() > 0; }, 10.0));
      streamer_ = std::make_unique<CmdVelStreamer>(g_ros->cmdVel());
    }
    return *streamer_;
  }

  /// Drives with (linear, angular) and returns `n` speed frames starting at the first moving one.
  std::vector<SeenFrame> driveAndCollect(double linear_x, double angular_z, std::size_t n) {
    const std::size_t from = base_->count();
    streamer().set(linear_x, angular_z);
    std::size_t start = 0;
    const bool moving = base_->waitUntil(
        [&](const std::vector<SeenFrame>& frames) {
          const auto first = firstMoving(frames, from);
          if (!first) return false;
          start = *first;
          return speedCount(frames, start) >= n;
        },
        15.0);
    EXPECT_TRUE(moving) << "no " << n << " moving speed frames for linear " << linear_x
                        << ", angular " << angular_z;
    std::vector<SeenFrame> speed = speedFramesFrom(base_->frames(), start);
    if (speed.size() > n) speed.resize(n);
    return speed;
  }

  std::unique_ptr<FakeBase> base_;
  std::unique_ptr<CmdVelStreamer> streamer_;
};

}  // namespace base_node_test
