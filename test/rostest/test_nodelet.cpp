// DriverNodelet in a nodelet manager (nodelet.test): it drives the base like driver_node, names
// its diagnostics after itself (not after the manager), and leaves a zero-speed frame as the last
// frame on the wire both when it is unloaded and when its manager is stopped with SIGINT.
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <sys/wait.h>

#include <csignal>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/Telemetry.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/fake_device.h"
#include "support/framer_configs.h"
#include "support/golden_frames.h"
#include "support/process_support.h"
#include "support/ros_test_support.h"

namespace {

using test_support::FakeDevice;
using test_support::waitFor;
namespace protocol = serial_robot_driver::protocol;

// A base speed frame (protocol section 1): 55 AA 09 seq 01, left int32 BE, right int32 BE, XOR.
bool isSpeedFrame(const FakeDevice::Frame& f) { return f.bytes.size() == 14 && f.bytes[4] == 0x01; }
bool isZeroSpeed(const FakeDevice::Frame& f) {
  if (!isSpeedFrame(f)) return false;
  for (std::size_t i = 5; i < 13; ++i) {
    if (f.bytes[i] != 0) return false;
  }
  return true;
}
bool isMoving(const FakeDevice::Frame& f) { return isSpeedFrame(f) && !isZeroSpeed(f); }

std::vector<FakeDevice::Frame> speedFrames(const FakeDevice& device) {
  std::vector<FakeDevice::Frame> speed;
  for (const auto& f : device.frames()) {
    if (isSpeedFrame(f)) speed.push_back(f);
  }
  return speed;
}

std::unique_ptr<FakeDevice> makeBase(const std::string& port) {
  auto base = std::make_unique<FakeDevice>(port, test_support::driverFramer({"base"}));
  base->plug();
  return base;
}

/// Publishes a forward cmd_vel at 20 Hz until destroyed (the driver keeps moving meanwhile).
class Driving {
 public:
  explicit Driving(const std::string& topic) {
    ros::NodeHandle nh;
    pub_ = nh.advertise<geometry_msgs::Twist>(topic, 10);
    thread_ = std::thread([this] {
      geometry_msgs::Twist twist;
      twist.linear.x = 0.5;
      while (!stop_) {
        pub_.publish(twist);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }
  ~Driving() {
    stop_ = true;
    thread_.join();
  }
  bool connected(double timeout_s) const {
    return waitFor([&] { return pub_.getNumSubscribers() > 0; }, timeout_s);
  }

 private:
  ros::Publisher pub_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// Waits for the frames to stop, then checks the last speed frame is zero and the one before moved.
void expectLastFrameIsZero(const FakeDevice& base) {
  // No new frame for half a second: the port is closed.
  std::size_t count = base.frameCount();
  for (int i = 0; i < 100; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    const std::size_t now = base.frameCount();
    if (now == count) break;
    count = now;
  }
  const std::vector<FakeDevice::Frame> speed = speedFrames(base);
  ASSERT_GE(speed.size(), 2u);
  EXPECT_TRUE(isZeroSpeed(speed.back())) << "the last speed frame is not zero";
  EXPECT_TRUE(isMoving(speed[speed.size() - 2])) << "the wheels had already stopped before";
  EXPECT_EQ(base.frames().back().bytes, speed.back().bytes);
}

// 1. Loaded by driver.launch nodelet:=true: drives the base, publishes "driver_node: base" and
// "driver_node: port <path>" (the nodelet's name, not the manager's), and an unload through the
// manager's service stops the wheels before the port closes.
TEST(DriverNodelet, DrivesAndStopsTheWheelsOnUnload) {
  std::string port;
  ASSERT_TRUE(ros::param::get("/driver_node/port", port));
  auto base = makeBase(port);
  ros::NodeHandle nh;
  test_support::DiagnosticsWatch diagnostics(nh, "driver_node");

  Driving driving("/cmd_vel");
  ASSERT_TRUE(driving.connected(30.0)) << "the nodelet does not subscribe to cmd_vel";
  ASSERT_TRUE(base->waitForFrames(
      [](const std::vector<FakeDevice::Frame>& frames) {
        int moving = 0;
        for (const auto& f : frames) moving += isMoving(f) ? 1 : 0;
        return moving >= 10;
      },
      20.0));
  ASSERT_TRUE(waitFor([&] { return diagnostics.latest("base").received > 0; }, 10.0));
  EXPECT_GT(diagnostics.latest("port " + port).received, 0u);
  EXPECT_EQ(diagnostics.latest("port " + port).value("path"), port);

  // The nodelet offers the node's runtime tuning: ~base's dynamic_reconfigure server.
  dynamic_reconfigure::Reconfigure tune;
  dynamic_reconfigure::DoubleParameter limit;
  limit.name = "max_wheel_speed";
  limit.value = 0.3;
  tune.request.config.doubles.push_back(limit);
  ASSERT_TRUE(ros::service::waitForService("/driver_node/base/set_parameters", 10000));
  ASSERT_TRUE(test_support::callService("/driver_node/base/set_parameters", tune));
  bool answered = false;
  for (const auto& value : tune.response.config.doubles) {
    if (value.name == "max_wheel_speed") answered = value.value == 0.3;
  }
  EXPECT_TRUE(answered) << "the answer shows the new limit";
  double in_force = 0;
  ASSERT_TRUE(ros::param::get("/driver_node/base/max_wheel_speed", in_force));
  EXPECT_DOUBLE_EQ(in_force, 0.3);

  nodelet::NodeletUnload unload;
  unload.request.name = "/driver_node";
  ASSERT_TRUE(ros::service::waitForService("/driver_nodelet_manager/unload_nodelet", 10000));
  ASSERT_TRUE(test_support::callService("/driver_nodelet_manager/unload_nodelet", unload));
  EXPECT_TRUE(unload.response.success);
  expectLastFrameIsZero(*base);
}

// 2. A manager of the test's own, stopped with SIGINT while the nodelet drives: the manager's
// teardown destroys the nodelet, which writes the zero-speed frame; the manager exits.
TEST(DriverNodelet, ManagerSigintStopsTheWheels) {
  std::string port;
  ASSERT_TRUE(ros::param::get("/driver_node/port", port));
  port += "_sigint";
  auto base = makeBase(port);
  ros::param::set("/sig/driver_node/port", port);
  ros::param::set("/sig/driver_node/base/battery_poll_rate", 0.0);
  ros::param::set("/sig/driver_node/body/enabled", false);
  ros::param::set("/sig/driver_node/servo_bus/enabled", false);

  test_support::ChildProcess manager("rosrun",
                                     {"nodelet", "nodelet", "manager", "__name:=sig_manager"});
  ASSERT_TRUE(manager.started());
  ASSERT_TRUE(ros::service::waitForService("/sig_manager/load_nodelet", 30000)) << manager.output();
  nodelet::NodeletLoad load;
  load.request.name = "/sig/driver_node";
  load.request.type = "serial_robot_driver/DriverNodelet";
  ASSERT_TRUE(test_support::callService("/sig_manager/load_nodelet", load)) << manager.output();
  ASSERT_TRUE(load.response.success) << manager.output();

  Driving driving("/sig/cmd_vel");
  ASSERT_TRUE(driving.connected(30.0)) << manager.output();
  ASSERT_TRUE(base->waitForFrames(
      [](const std::vector<FakeDevice::Frame>& frames) {
        int moving = 0;
        for (const auto& f : frames) moving += isMoving(f) ? 1 : 0;
        return moving >= 10;
      },
      20.0))
      << manager.output();

  manager.signal(SIGINT);
  const auto status = manager.waitExit(20.0);
  ASSERT_TRUE(status.has_value()) << "the manager did not exit on SIGINT\n" << manager.output();
  expectLastFrameIsZero(*base);
}

// 3. ~replay_bag in the nodelet: the bag's chunks are replayed (telemetry with the recorded
// stamps), and the real port, though it exists and a base is configured on it, is never opened:
// nothing is written to it. A bag that cannot be replayed is refused, naming the bag, and again
// nothing touches the port.
class NodeletReplay : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ros::param::get("/driver_node/port", port_));
    port_ += "_replay";
    base_ = makeBase(port_);
  }

  /// Loads a DriverNodelet named `name` into a manager of its own, replaying `bag`.
  void load(const std::string& name, const std::string& bag) {
    ros::param::set(name + "/port", port_);
    ros::param::set(name + "/replay_bag", bag);
    ros::param::set(name + "/replay_rate", 0.0);
    ros::param::set(name + "/base/battery_poll_rate", 0.0);
    ros::param::set(name + "/servo_bus/enabled", false);
    ros::param::set(name + "/body/servo_ids", std::vector<int>{1, 2});
    ros::param::set(name + "/body/joint_names", std::vector<std::string>{"a", "b"});
    ros::param::set(name + "/body/zero_ticks", std::vector<int>{2048, 2048});
    ros::param::set(name + "/body/directions", std::vector<int>{1, 1});
    manager_ = std::make_unique<test_support::ChildProcess>(
        "rosrun", std::vector<std::string>{"nodelet", "nodelet", "manager", "__name:=replay_manager"});
    ASSERT_TRUE(ros::service::waitForService("/replay_manager/load_nodelet", 30000))
        << manager_->output();
    nodelet::NodeletLoad request;
    request.request.name = name;
    request.request.type = "serial_robot_driver/DriverNodelet";
    ASSERT_TRUE(test_support::callService("/replay_manager/load_nodelet", request))
        << manager_->output();
    ASSERT_TRUE(request.response.success) << manager_->output();
  }

  void TearDown() override {
    if (manager_ && manager_->running()) {
      manager_->signal(SIGINT);
      manager_->waitExit(20.0);
    }
    std::remove(bag_.c_str());
  }

  std::string port_;
  std::string bag_ = "/tmp/srd_test_nodelet_replay_" + std::to_string(::getpid()) + ".bag";
  std::unique_ptr<FakeDevice> base_;
  std::unique_ptr<test_support::ChildProcess> manager_;
};

TEST_F(NodeletReplay, ReplaysTheBagWithoutOpeningThePort) {
  constexpr int kFrames = 10;
  {
    rosbag::Bag bag(bag_, rosbag::bagmode::Write);
    serial_robot_driver::SerialChunk chunk;
    chunk.port = port_;
    chunk.header.stamp = ros::Time(100.0);
    bag.write("/serial_raw", chunk.header.stamp, chunk);  // the "port opened" mark
    for (int i = 0; i < kFrames; ++i) {
      chunk.header.stamp = ros::Time(100.0 + 0.02 * (i + 1));
      chunk.data = golden::body::kTelemetryTwoServos;
      bag.write("/serial_raw", chunk.header.stamp, chunk);
    }
  }
  ros::NodeHandle nh;
  test_support::TopicCounter<serial_robot_driver::Telemetry> telemetry(nh, "/replaying/telemetry");
  load("/replaying/driver_node", bag_);
  ASSERT_TRUE(telemetry.waitForCount(kFrames, 30.0)) << telemetry.count() << " telemetry\n"
                                                    << manager_->output();
  const auto replayed = telemetry.since(0);
  EXPECT_EQ(replayed.front().header.stamp, ros::Time(100.02));
  EXPECT_EQ(replayed.back().header.stamp, ros::Time(100.0 + 0.02 * kFrames));
  // A live base would have sent its Reset by now.
  test_support::sleepSeconds(1.0);
  EXPECT_TRUE(base_->frames().empty()) << "the replaying nodelet wrote to the real port";
}

TEST_F(NodeletReplay, RefusesABagItCannotReplayNamingIt) {
  const std::string missing = "/tmp/srd_test_nodelet_no_such_" + std::to_string(::getpid()) + ".bag";
  load("/refusing/driver_node", missing);
  // The manager's own output (its console log) carries the refusal.
  const bool refused = waitFor(
      [&] {
        const std::string output = manager_->output();
        const std::size_t line = output.find("replay bag " + missing);
        return line != std::string::npos && output.find("does not start", line) != std::string::npos;
      },
      30.0);
  EXPECT_TRUE(refused) << manager_->output();
  test_support::sleepSeconds(1.0);
  EXPECT_TRUE(base_->frames().empty()) << "the refused nodelet wrote to the real port";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_nodelet");
  return RUN_ALL_TESTS();
}
