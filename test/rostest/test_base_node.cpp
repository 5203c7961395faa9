// End-to-end tests of driver_node with the AP1 wheeled base (docs/protocols.md, section 1).
//
// base_node.test launches driver_node with only the base enabled, on a pty path this test creates.
// The test plays the base: it reads every byte the node writes, splits it into frames with the
// project's StreamFramer, and checks the frames byte for byte (expected frames are written out by
// hand below) and through the node's topics and services. A few tests start their own driver_node
// process (port missing at start, bad parameter, SIGINT).
//
// Every TEST starts on a fresh pty, so the node reconnects and no state leaks between tests. The
// machine may be busy: the tests count frames and use generous deadlines, never tight timing.
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
#include "serial_robot_driver/protocol/base_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
#include "support/ros_test_support.h"

namespace {

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
Bytes withXor(Bytes frame) {
  uint8_t x = 0;
  for (uint8_t b : frame) x ^= b;
  frame.push_back(x);
  return frame;
}

Bytes resetFrame(uint8_t seq) { return withXor({0x55, 0xAA, 0x02, seq, 0x05, 0x00}); }
Bytes clearEncodersFrame(uint8_t seq) { return withXor({0x55, 0xAA, 0x02, seq, 0x06, 0x00}); }
Bytes batteryRequestFrame(uint8_t seq) { return withXor({0x55, 0xAA, 0x02, seq, 0x02, 0x00}); }
Bytes zeroSpeedFrame(uint8_t seq) {
  return withXor({0x55, 0xAA, 0x09, seq, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00});
}

// Base -> host frames, written out by hand (XOR included).
const Bytes& kTimeoutErrorFrame = golden::base::kErrorStatusSeq32;     // FF status
const Bytes& kBattery87PercentFrame = golden::base::kBattery87ReplySeq16;  // 0x57 = 87 %

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
      const auto decoded = protocol::base::decodeFrame(frame.bytes.data(), frame.bytes.size());
      if (frame.family != protocol::base::kFrames || !decoded) continue;
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
    config.base = true;
    return config;
  }

  test_support::FakeDevice device_;
};

// Frame-list helpers ----------------------------------------------------------------------------

std::vector<SeenFrame> speedFramesFrom(const std::vector<SeenFrame>& frames, std::size_t from) {
  std::vector<SeenFrame> out;
  for (std::size_t i = from; i < frames.size(); ++i) {
    if (frames[i].isSpeed()) out.push_back(frames[i]);
  }
  return out;
}

std::optional<std::size_t> findFrom(const std::vector<SeenFrame>& frames, std::size_t from,
                                    const std::function<bool(const SeenFrame&)>& pred) {
  for (std::size_t i = from; i < frames.size(); ++i) {
    if (pred(frames[i])) return i;
  }
  return std::nullopt;
}

bool isZeroSpeedFrame(const SeenFrame& f) { return f.isZeroSpeed(); }

/// Index of the first speed frame at or after `from` that moves a wheel.
std::optional<std::size_t> firstMoving(const std::vector<SeenFrame>& frames, std::size_t from) {
  return findFrom(frames, from, [](const SeenFrame& f) { return f.isSpeed() && !f.isZeroSpeed(); });
}

/// Number of speed frames at or after `from`.
std::size_t speedCount(const std::vector<SeenFrame>& frames, std::size_t from) {
  std::size_t n = 0;
  for (std::size_t i = from; i < frames.size(); ++i) n += frames[i].isSpeed() ? 1 : 0;
  return n;
}

double meanLeft(const std::vector<SeenFrame>& speed) {
  double sum = 0;
  for (const auto& f : speed) sum += f.left();
  return speed.empty() ? 0.0 : sum / speed.size();
}
double meanRight(const std::vector<SeenFrame>& speed) {
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
  explicit RosSide(const std::string& node_name) : diagnostics_(nh_, node_name) {
    cmd_vel_ = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
    wheel_sub_ = nh_.subscribe("wheel_command", 1000, &RosSide::onWheelCommand, this);
    battery_sub_ = nh_.subscribe("battery", 10, &RosSide::onBattery, this);
  }

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

  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher cmd_vel_;
  ros::Subscriber wheel_sub_, battery_sub_;
  mutable std::mutex mutex_;
  std::vector<TimedWheelCommand> wheel_commands_;
  std::vector<sensor_msgs::BatteryState> battery_;
};

RosSide* g_ros = nullptr;
std::string g_port;         // the pty path driver_node was given
std::string g_driver_path;  // the driver_node executable, for the tests that start their own

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
std::vector<std::string> driverArgs(const std::string& ns, const std::string& name,
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
    base_ = std::make_unique<FakeBase>(g_port);
    // The first test also waits for the node to start; later ones only for its reconnect.
    ASSERT_TRUE(base_->waitForCount(2, 20.0)) << "driver_node never wrote to " << g_port;
    if (g_ros->wheelCommands().empty()) {
      // First test: the wheel_command subscription may have connected after the node's first
      // frames. Once messages flow, start over on a fresh pty so no frame goes unreported.
      ASSERT_TRUE(waitFor([] { return !g_ros->wheelCommands().empty(); }, 10.0))
          << "no wheel_command messages";
      base_->unplug();
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      base_->plug();
      ASSERT_TRUE(base_->waitForCount(2, 10.0)) << "driver_node did not reconnect";
    }
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

// The hand-written XOR helper reproduces the golden vectors of docs/protocols.md, so the expected
// frames built with it below can be trusted.
TEST(BaseGoldenFrames, HelperMatchesProtocolVectors) {
  EXPECT_EQ(resetFrame(0x02), golden::base::kResetSeq2);
  EXPECT_EQ(batteryRequestFrame(0x01), golden::base::kBatteryRequestSeq1);
  EXPECT_EQ(clearEncodersFrame(0x03), golden::base::kClearEncodersSeq3);
  EXPECT_EQ(withXor({0x55, 0xAA, 0x09, 0x00, 0x01, 0xFF, 0xFA, 0xFF, 0xFA, 0x00, 0x00, 0x00, 0x00}),
            golden::base::kBothMinus6Seq0);
}

// 1. After connecting, the node sends a Reset, then a speed frame reported with reset_before.
TEST_F(BaseNodeTest, ResetIsTheFirstFrameAfterConnect) {
  const std::vector<SeenFrame> frames = base_->frames();
  ASSERT_GE(frames.size(), 2u);
  EXPECT_EQ(frames[0].bytes, resetFrame(frames[0].seq));
  ASSERT_TRUE(frames[1].isSpeed()) << "MSGID " << int(frames[1].msg_id);
  EXPECT_EQ(frames[1].seq, static_cast<uint8_t>(frames[0].seq + 1));
  EXPECT_EQ(frames[1].bytes.size(), 14u);

  ASSERT_TRUE(g_ros->waitWheelCommand(frames[1].seq, base_->pluggedAt(), 5.0));
  const auto command = g_ros->wheelCommand(frames[1].seq, base_->pluggedAt());
  EXPECT_TRUE(command->reset_before);
  EXPECT_EQ(command->left_ticks, frames[1].left());
  EXPECT_EQ(command->right_ticks, frames[1].right());

  // A later speed frame with no Reset just before it is reported without reset_before.
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  const std::vector<SeenFrame> later = base_->frames();
  const auto plain = findFrom(later, 3, [&](const SeenFrame& f) { return f.isSpeed(); });
  ASSERT_TRUE(plain.has_value());
  ASSERT_FALSE(later[*plain - 1].isReset());
  ASSERT_TRUE(g_ros->waitWheelCommand(later[*plain].seq, base_->pluggedAt(), 5.0));
  EXPECT_FALSE(g_ros->wheelCommand(later[*plain].seq, base_->pluggedAt())->reset_before);
}

// 2. With no cmd_vel the node keeps sending zero-speed frames (the base's heartbeat) at the loop
// rate; SEQ goes up by one per frame and wraps 255 -> 0.
TEST_F(BaseNodeTest, HeartbeatFlowsWithoutCmdVelAndSeqWraps) {
  const std::size_t from = base_->count();
  const Clock::time_point start = Clock::now();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const std::vector<SeenFrame> window = base_->frames();
  std::size_t in_window = 0;
  for (std::size_t i = from; i < window.size(); ++i) {
    if (!window[i].isSpeed()) continue;
    if (window[i].arrival - start > std::chrono::seconds(2)) break;
    EXPECT_TRUE(window[i].isZeroSpeed()) << "frame " << i;
    EXPECT_EQ(window[i].bytes, zeroSpeedFrame(window[i].seq)) << "frame " << i;
    ++in_window;
  }
  // 50 Hz for 2 s; a wide band, the machine may be busy.
  EXPECT_GE(in_window, 60u);
  EXPECT_LE(in_window, 120u);

  // SEQ wraps after 256 frames (about 5 s at 50 Hz plus the battery requests).
  const bool wrapped = base_->waitUntil(
      [](const std::vector<SeenFrame>& frames) {
        for (std::size_t i = 1; i < frames.size(); ++i) {
          if (frames[i - 1].seq == 255 && frames[i].seq == 0) return true;
        }
        return false;
      },
      15.0);
  EXPECT_TRUE(wrapped) << "no 255 -> 0 SEQ wrap seen";
  const std::vector<SeenFrame> all = base_->frames();
  for (std::size_t i = 1; i < all.size(); ++i) {
    ASSERT_EQ(all[i].seq, static_cast<uint8_t>(all[i - 1].seq + 1)) << "frame " << i;
  }
}

// 3a. Straight ahead at 0.2 m/s: both wheels forward, 8.149 ticks per period on average.
TEST_F(BaseNodeTest, StraightDrivesBothWheelsForward) {
  const std::vector<SeenFrame> speed = driveAndCollect(0.2, 0.0, 60);
  ASSERT_EQ(speed.size(), 60u);
  for (const auto& f : speed) {
    EXPECT_EQ(f.left(), f.right());
    EXPECT_TRUE(f.left() == 8 || f.left() == 9) << f.left();
  }
  EXPECT_NEAR(meanLeft(speed), 0.2 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanRight(speed), 0.2 * kTicksAt1Mps, 0.05);
}

// 3b. Turning in place at 0.5 rad/s: left backward, right forward, 0.1 m/s = 4.074 ticks each.
TEST_F(BaseNodeTest, TurnInPlaceSpinsWheelsOpposite) {
  const std::vector<SeenFrame> speed = driveAndCollect(0.0, 0.5, 60);
  ASSERT_EQ(speed.size(), 60u);
  for (const auto& f : speed) {
    EXPECT_LT(f.left(), 0);
    EXPECT_GT(f.right(), 0);
    EXPECT_LE(std::abs(f.left() + f.right()), 2) << f.left() << " " << f.right();
  }
  EXPECT_NEAR(meanLeft(speed), -0.1 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanRight(speed), 0.1 * kTicksAt1Mps, 0.05);
}

// 4. 0.02 m/s is 0.815 ticks per period: the vendor's truncation would send 0 forever; carrying
// the remainder moves the robot at the right speed on average.
TEST_F(BaseNodeTest, LowSpeedMovesOnAverage) {
  const std::vector<SeenFrame> speed = driveAndCollect(0.02, 0.0, 120);
  ASSERT_EQ(speed.size(), 120u);
  int zeros = 0;
  for (const auto& f : speed) {
    EXPECT_TRUE(f.left() == 0 || f.left() == 1) << f.left();
    EXPECT_EQ(f.left(), f.right());
    zeros += f.left() == 0 ? 1 : 0;
  }
  EXPECT_GT(zeros, 0);
  EXPECT_NEAR(meanLeft(speed), 0.02 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanRight(speed), 0.02 * kTicksAt1Mps, 0.05);
}

// 5. 3 m/s with 1 rad/s asks for 2.8 / 3.2 m/s: both wheels are scaled by 1/3.2, so the right
// wheel runs at max_wheel_speed (1 m/s = 40.74 ticks) and the left at 0.875 m/s (35.65 ticks).
TEST_F(BaseNodeTest, FastCommandIsClampedKeepingTheTurnRadius) {
  const std::vector<SeenFrame> speed = driveAndCollect(3.0, 1.0, 60);
  ASSERT_EQ(speed.size(), 60u);
  for (const auto& f : speed) {
    EXPECT_TRUE(f.right() == 40 || f.right() == 41) << f.right();
    EXPECT_TRUE(f.left() == 35 || f.left() == 36) << f.left();
  }
  EXPECT_NEAR(meanRight(speed), kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanLeft(speed), 0.875 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanLeft(speed) / meanRight(speed), 2.8 / 3.2, 0.005);
}

// 6. When cmd_vel stops for longer than cmd_vel_timeout (0.5 s), the wheels are stopped.
TEST_F(BaseNodeTest, CmdVelTimeoutStopsTheWheels) {
  const std::vector<SeenFrame> moving = driveAndCollect(0.2, 0.0, 10);
  ASSERT_EQ(moving.size(), 10u);
  streamer_->stop(false);  // silence, not a zero Twist
  const std::size_t from = base_->count();
  std::size_t first_zero = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto zero = findFrom(frames, from, isZeroSpeedFrame);
        if (!zero) return false;
        first_zero = *zero;
        return speedCount(frames, first_zero) >= 25;
      },
      5.0));
  const std::vector<SeenFrame> after = speedFramesFrom(base_->frames(), first_zero);
  for (const auto& f : after) EXPECT_TRUE(f.isZeroSpeed()) << f.left() << " " << f.right();
}

// 7. A NaN cmd_vel is rejected as "stop", counted in the diagnostics, and the node keeps working.
TEST_F(BaseNodeTest, NanCmdVelStopsTheWheels) {
  ASSERT_EQ(driveAndCollect(0.2, 0.0, 10).size(), 10u);
  const std::string kRejected = "rejected cmd_vel (NaN/Inf)";
  ASSERT_TRUE(waitFor([&] { return !g_ros->baseDiagnostics().value(kRejected).empty(); }, 5.0));
  const uint64_t rejected_before = g_ros->baseDiagnostics().number(kRejected);

  const std::size_t from = base_->count();
  streamer().set(std::numeric_limits<double>::quiet_NaN(), 0.0);  // keeps streaming NaN
  std::size_t first_zero = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto zero = findFrom(frames, from, isZeroSpeedFrame);
        if (!zero) return false;
        first_zero = *zero;
        return speedCount(frames, first_zero) >= 40;
      },
      5.0));
  for (const auto& f : speedFramesFrom(base_->frames(), first_zero)) {
    EXPECT_TRUE(f.isZeroSpeed()) << f.left() << " " << f.right();
  }
  EXPECT_TRUE(
      waitFor([&] { return g_ros->baseDiagnostics().number(kRejected) > rejected_before; }, 5.0))
      << "the NaN cmd_vel was not counted as rejected";

  // Still alive and driving.
  EXPECT_EQ(driveAndCollect(0.2, 0.0, 5).size(), 5u);
}

// 8. An FF timeout-error frame from the base makes the node send a Reset before its next speed
// frame, at once rather than after a long delay.
TEST_F(BaseNodeTest, TimeoutErrorFromBaseTriggersReset) {
  // Settled: no Reset in a stretch of ordinary heartbeat frames.
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  const std::size_t settled = base_->count();
  ASSERT_TRUE(base_->waitForCount(settled + 15, 5.0));
  const std::vector<SeenFrame> before = base_->frames();
  ASSERT_FALSE(findFrom(before, settled, [](const SeenFrame& f) { return f.isReset(); }));

  const std::size_t from = base_->count();
  const Clock::time_point written = Clock::now();
  base_->write(kTimeoutErrorFrame);
  std::size_t reset = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto found = findFrom(frames, from, [](const SeenFrame& f) { return f.isReset(); });
        if (!found || *found + 1 >= frames.size()) return false;
        reset = *found;
        return true;
      },
      3.0))
      << "no Reset after the FF error frame";
  const std::vector<SeenFrame> frames = base_->frames();
  EXPECT_EQ(frames[reset].bytes, resetFrame(frames[reset].seq));
  ASSERT_TRUE(frames[reset + 1].isSpeed());
  EXPECT_EQ(frames[reset + 1].seq, static_cast<uint8_t>(frames[reset].seq + 1));
  // Frames written before the node read the FF frame may precede it, but only a few.
  EXPECT_LE(speedCount(std::vector<SeenFrame>(frames.begin(), frames.begin() + reset), from), 25u);
  ASSERT_TRUE(g_ros->waitWheelCommand(frames[reset + 1].seq, written, 5.0));
  EXPECT_TRUE(g_ros->wheelCommand(frames[reset + 1].seq, written)->reset_before);
}

// 9. Unplugging and replugging the adapter: the node reopens the port and starts with a Reset.
TEST_F(BaseNodeTest, ReconnectAfterUnplugStartsWithReset) {
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  base_->unplug();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the node notices the loss
  base_->plug();
  ASSERT_TRUE(base_->waitForCount(2, 10.0)) << "the node did not reconnect";
  const std::vector<SeenFrame> frames = base_->frames();
  EXPECT_EQ(frames[0].bytes, resetFrame(frames[0].seq));
  ASSERT_TRUE(frames[1].isSpeed());
  EXPECT_EQ(frames[1].seq, static_cast<uint8_t>(frames[0].seq + 1));
  ASSERT_TRUE(base_->waitForCount(20, 5.0)) << "frames stopped after the reconnect";
}

// 10. The node polls the battery; the base's reply is published as a BatteryState.
TEST_F(BaseNodeTest, BatteryReplyIsPublished) {
  const std::size_t from = base_->count();
  std::size_t request = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto found =
            findFrom(frames, from, [](const SeenFrame& f) { return f.msg_id == kMsgBattery; });
        if (found) request = *found;
        return found.has_value();
      },
      5.0))
      << "no battery request at battery_poll_rate 2 Hz";
  const std::vector<SeenFrame> frames = base_->frames();
  EXPECT_EQ(frames[request].bytes, batteryRequestFrame(frames[request].seq));

  const std::size_t replies_before = g_ros->battery().size();
  base_->write(kBattery87PercentFrame);
  ASSERT_TRUE(waitFor([&] { return g_ros->battery().size() > replies_before; }, 5.0));
  const sensor_msgs::BatteryState state = g_ros->battery().at(replies_before);
  EXPECT_NEAR(state.percentage, 0.87, 1e-6);
  EXPECT_TRUE(state.present);
}

// 10b. A base that never answers the battery requests (2 Hz) is an ERROR in /diagnostics once
// three poll periods passed (that a reply clears it is a BaseController unit test).
TEST_F(BaseNodeTest, SilentBaseIsADiagnosticsError) {
  ASSERT_TRUE(waitFor(
      [&] {
        const auto status = g_ros->baseDiagnostics();
        return status.level == 2 &&
               status.message.find("no reply from the base") != std::string::npos;
      },
      15.0))
      << "last base status: " << g_ros->baseDiagnostics().message;
  EXPECT_EQ(g_ros->baseDiagnostics().value("connected"), "True") << "the port itself is fine";
}

// 10c. Battery below base/battery_error_percent (10) is an ERROR, below base/battery_warn_percent
// (20) a WARN, as kobuki_node reports it.
TEST_F(BaseNodeTest, LowBatteryIsReportedInDiagnostics) {
  // Battery replies written by hand: 55 AA 02 SEQ 02 PCT XOR.
  const Bytes battery5 = {0x55, 0xAA, 0x02, 0x00, 0x02, 0x05, 0xFA};   // 5 %
  const Bytes battery15 = {0x55, 0xAA, 0x02, 0x01, 0x02, 0x0F, 0xF1};  // 15 %
  ASSERT_EQ(battery5, withXor({0x55, 0xAA, 0x02, 0x00, 0x02, 0x05}));
  ASSERT_EQ(battery15, withXor({0x55, 0xAA, 0x02, 0x01, 0x02, 0x0F}));
  base_->write(battery5);
  EXPECT_TRUE(waitFor(
      [&] {
        const auto status = g_ros->baseDiagnostics();
        return status.level == 2 && status.message.find("battery 5 % (below 10 %)") != std::string::npos;
      },
      10.0))
      << "last base status: " << g_ros->baseDiagnostics().message;
  base_->write(battery15);
  EXPECT_TRUE(waitFor(
      [&] {
        return g_ros->baseDiagnostics().message.find("battery 15 % (below 20 %)") != std::string::npos;
      },
      10.0))
      << "last base status: " << g_ros->baseDiagnostics().message;
}

// 11. base/reset and base/clear_encoders put their exact frames on the wire, in the SEQ sequence.
TEST_F(BaseNodeTest, ServicesWriteResetAndClearEncoders) {
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  const struct {
    const char* service;
    uint8_t msg_id;
    Bytes (*expected)(uint8_t);
  } cases[] = {{"base/reset", kMsgReset, resetFrame},
               {"base/clear_encoders", kMsgClearEncoders, clearEncodersFrame}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.service);
    ASSERT_TRUE(ros::service::waitForService(c.service, 10000));
    const std::size_t from = base_->count();
    std_srvs::Trigger trigger;
    ASSERT_TRUE(ros::service::call(c.service, trigger));
    EXPECT_TRUE(trigger.response.success) << trigger.response.message;
    std::size_t index = 0;
    ASSERT_TRUE(base_->waitUntil(
        [&](const std::vector<SeenFrame>& frames) {
          const auto found =
              findFrom(frames, from, [&](const SeenFrame& f) { return f.msg_id == c.msg_id; });
          if (!found || *found + 1 >= frames.size()) return false;
          index = *found;
          return true;
        },
        5.0));
    const std::vector<SeenFrame> frames = base_->frames();
    ASSERT_GE(index, 1u);
    const uint8_t seq = static_cast<uint8_t>(frames[index - 1].seq + 1);
    EXPECT_EQ(frames[index].bytes, c.expected(seq));
    EXPECT_EQ(frames[index + 1].seq, static_cast<uint8_t>(seq + 1));
    // Exactly one such frame for one call.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const std::vector<SeenFrame> later = base_->frames();
    EXPECT_FALSE(
        findFrom(later, index + 1, [&](const SeenFrame& f) { return f.msg_id == c.msg_id; }));
  }
}

// 12. A node started while its port does not exist yet keeps retrying and connects when the
// device appears, starting with a Reset.
TEST(BaseNodeProcess, ConnectsWhenThePortAppearsLater) {
  ASSERT_FALSE(g_driver_path.empty());
  const std::string port = g_port + "_late";
  test_support::removeStaleLink(port);
  ChildProcess node(g_driver_path, driverArgs("/late", "driver_late", port));
  ASSERT_TRUE(node.started());
  // Up and failing to open its port (its services exist once the base interface is built).
  ASSERT_TRUE(ros::service::waitForService("/late/base/reset", 20000)) << node.output();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_TRUE(node.running()) << node.output();

  FakeBase base(port);
  ASSERT_TRUE(base.waitForCount(2, 10.0)) << "no frames after the port appeared\n" << node.output();
  const std::vector<SeenFrame> frames = base.frames();
  EXPECT_EQ(frames[0].bytes, resetFrame(frames[0].seq));
  EXPECT_TRUE(frames[1].isSpeed());

  node.signal(SIGTERM);
  const auto status = node.waitExit(10.0);
  ASSERT_TRUE(status.has_value()) << "driver_node did not exit on SIGTERM";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << node.output();
}

// 13. A bad parameter stops the node at start-up with a non-zero status and names the parameter.
// A speed limit of 0 is one: it would not mean "no limit".
TEST(BaseNodeProcess, BadParameterExitsNamingIt) {
  ASSERT_FALSE(g_driver_path.empty());
  const std::vector<std::pair<std::string, std::string>> cases = {{"base/wheel_diameter", "-1"},
                                                                  {"base/max_wheel_speed", "0.0"},
                                                                  {"base/max_wheel_speed", "-0.5"}};
  int run = 0;
  for (const auto& [name, value] : cases) {
    SCOPED_TRACE(name + " " + value);
    // A node name of its own each time: `_name:=value` stays on the parameter server.
    std::vector<std::string> args =
        driverArgs("/bad", "driver_bad" + std::to_string(run++), g_port + "_bad");
    args.push_back("_" + name + ":=" + value);
    ChildProcess node(g_driver_path, args);
    ASSERT_TRUE(node.started());
    const auto status = node.waitExit(20.0);
    ASSERT_TRUE(status.has_value()) << "driver_node kept running with " << name << " " << value;
    ASSERT_TRUE(WIFEXITED(*status)) << node.output();
    EXPECT_EQ(WEXITSTATUS(*status), 2);
    EXPECT_NE(node.output().find(name), std::string::npos) << node.output();
  }
}

// 14. SIGINT while driving: the node's last frame before it closes the port is a zero-speed frame,
// and it exits cleanly.
TEST(BaseNodeProcess, SigintStopsTheWheelsBeforeExit) {
  ASSERT_FALSE(g_driver_path.empty());
  const std::string port = g_port + "_sigint";
  FakeBase base(port);
  ChildProcess node(g_driver_path, driverArgs("/sig", "driver_sigint", port));
  ASSERT_TRUE(node.started());
  ros::Publisher cmd_vel = g_ros->nh().advertise<geometry_msgs::Twist>("/sig/cmd_vel", 10);
  ASSERT_TRUE(waitFor([&] { return cmd_vel.getNumSubscribers() > 0; }, 20.0)) << node.output();

  CmdVelStreamer streamer(cmd_vel);
  streamer.set(0.5, 0.0);  // 20.37 ticks per period
  ASSERT_TRUE(base.waitUntil(
      [](const std::vector<SeenFrame>& frames) {
        const auto first = firstMoving(frames, 0);
        return first && speedCount(frames, *first) >= 10;
      },
      10.0))
      << node.output();

  node.signal(SIGINT);  // the streamer keeps going: the stop must come from the shutdown
  const auto status = node.waitExit(10.0);
  streamer.stop(false);
  ASSERT_TRUE(status.has_value()) << "driver_node did not exit on SIGINT";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << node.output();

  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last bytes
  const std::vector<SeenFrame> speed = speedFramesFrom(base.frames(), 0);
  ASSERT_GE(speed.size(), 2u);
  const SeenFrame& last = speed.back();
  const SeenFrame& before_last = speed[speed.size() - 2];
  EXPECT_EQ(last.bytes, zeroSpeedFrame(last.seq));
  EXPECT_EQ(last.seq, static_cast<uint8_t>(before_last.seq + 1));
  EXPECT_FALSE(before_last.isZeroSpeed()) << "the wheels had already stopped before the SIGINT";
  EXPECT_EQ(base.frames().back().bytes, last.bytes);
  EXPECT_EQ(base.garbage(), 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_base_node");
  ros::NodeHandle private_nh("~");

  std::string node_name = "driver_node";
  private_nh.getParam("node_name", node_name);
  if (!ros::param::get("/" + node_name + "/port", g_port) || g_port.empty()) {
    std::fprintf(stderr, "cannot read /%s/port from the parameter server\n", node_name.c_str());
    return 1;
  }
  g_driver_path = test_support::findDriverNode();

  RosSide ros_side(node_name);
  g_ros = &ros_side;
  const int result = RUN_ALL_TESTS();
  g_ros = nullptr;
  return result;
}
