// Capture and replay, round trip (replay.test):
//  1. /live/driver_node runs with ~capture against the simulator (sim::RobotSim in this process,
//     100 Hz telemetry with the foot block on every other frame, battery replies) injecting junk
//     bursts, corrupt checksums, lost bytes and unplugs. The test records serial_raw and the
//     published joint_states, imu/data, telemetry, foot_pressure and battery, and the node's final
//     diagnostics counters. The simulator starts only once every subscription is connected, so the
//     capture holds the port's very first open.
//  2. The chunks go into a bag (rosbag C++ API); /replayed/driver_node replays it at full speed
//     (~replay_rate 0) and must exit 0 by itself at the end of the bag.
//  3. Message by message, the replayed topics equal the live ones: count, stamps and every field
//     (the header's seq aside: roscpp numbers each publisher's messages itself); and the framer,
//     body and base counters of the replay's diagnostics equal the live ones.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "serial_robot_driver/FootPressure.h"
#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/Telemetry.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::DiagnosticsWatch;
using test_support::TopicCounter;

/// The message's bytes with header.seq zeroed: everything the driver put into it.
template <typename Msg>
std::vector<uint8_t> contentOf(Msg msg) {
  msg.header.seq = 0;
  const uint32_t size = ros::serialization::serializationLength(msg);
  std::vector<uint8_t> bytes(size);
  ros::serialization::OStream stream(bytes.data(), size);
  ros::serialization::serialize(stream, msg);
  return bytes;
}

/// Live and replayed messages of one topic, in publication order.
template <typename Msg>
struct TopicPair {
  TopicPair(ros::NodeHandle& nh, const std::string& topic)
      : name(topic), live(nh, "/live/" + topic), replayed(nh, "/replayed/" + topic) {}

  void expectEqual() const {
    const std::vector<Msg> a = live.since(0);
    const std::vector<Msg> b = replayed.since(0);
    ASSERT_GT(a.size(), 0u) << name << ": nothing published live";
    ASSERT_EQ(a.size(), b.size()) << name << ": live and replayed counts differ";
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].header.stamp, b[i].header.stamp) << name << " message " << i;
      ASSERT_EQ(contentOf(a[i]), contentOf(b[i])) << name << " message " << i << " differs";
    }
  }

  std::string name;
  TopicCounter<Msg> live;
  TopicCounter<Msg> replayed;
};

std::string livePort() {
  std::string port;
  ros::param::get("/live/driver_node/port", port);
  return port;
}

TEST(Replay, PublishesExactlyWhatWentOutLive) {
  ros::NodeHandle nh;
  const std::string port = livePort();
  ASSERT_FALSE(port.empty());
  test_support::removeStaleLink(port);

  TopicPair<sensor_msgs::JointState> joint_states(nh, "joint_states");
  TopicPair<sensor_msgs::Imu> imu(nh, "imu/data");
  TopicPair<srd::Telemetry> telemetry(nh, "telemetry");
  TopicPair<srd::FootPressure> foot_pressure(nh, "foot_pressure");
  TopicPair<sensor_msgs::BatteryState> battery(nh, "battery");
  TopicCounter<srd::SerialChunk> serial_raw(nh, "/live/serial_raw");
  DiagnosticsWatch live_diagnostics(nh, "live/driver_node");
  DiagnosticsWatch replayed_diagnostics(nh, "replayed/driver_node");

  // 1. Live, with faults. Everything listens before the first byte moves.
  ASSERT_TRUE(serial_raw.waitConnected(30.0));
  ASSERT_TRUE(joint_states.live.waitConnected(30.0));
  ASSERT_TRUE(imu.live.waitConnected(30.0));
  ASSERT_TRUE(telemetry.live.waitConnected(30.0));
  ASSERT_TRUE(foot_pressure.live.waitConnected(30.0));
  ASSERT_TRUE(battery.live.waitConnected(30.0));
  ros::WallDuration(0.5).sleep();  // the driver's side of each connection settles too

  sim::SimOptions options;
  options.link = port;
  serial_robot_driver::devices::body::sim::bodyConfig(options).servo_ids = {1, 2, 3};
  serial_robot_driver::devices::body::sim::bodyConfig(options).telemetry_rate_hz = 100;
  serial_robot_driver::devices::body::sim::bodyConfig(options).foot_mode =
      serial_robot_driver::devices::body::sim::FootMode::kAlternate;
  options.faults.seed = 12;
  options.faults.garbage_rate_hz = 4;
  options.faults.corrupt_rate = 0.05;
  options.faults.drop_rate = 0.03;
  options.faults.unplug_every_s = 2.5;
  options.faults.unplug_duration_s = 0.4;
  {
    sim::RobotSim robot(options);
    robot.start();
    ASSERT_TRUE(telemetry.live.waitForCount(600, 60.0));
    robot.stop();
  }  // the pty closes: no byte moves any more
  // Let the last messages and a diagnostics period with the final counters arrive.
  const uint64_t port_statuses = live_diagnostics.latest("port " + port).received;
  ASSERT_TRUE(live_diagnostics.waitFor(
      "port " + port, port_statuses + 1, [](const DiagnosticsWatch::Status&) { return true; },
      [] { return ros::ok(); }, 10.0));
  ros::WallDuration(1.5).sleep();
  const DiagnosticsWatch::Status live_port = live_diagnostics.latest("port " + port);
  const DiagnosticsWatch::Status live_body = live_diagnostics.latest("body");
  const DiagnosticsWatch::Status live_base = live_diagnostics.latest("base");
  ASSERT_GE(live_port.number("connects"), 2u) << "no unplug happened";
  ASSERT_GT(live_port.number("checksum errors"), 0u) << "no corrupt frame arrived";
  ASSERT_GT(live_port.number("bytes skipped (resync)"), 0u) << "no junk arrived";
  ASSERT_EQ(live_diagnostics.latest("wire capture").number("chunks dropped"), 0u);

  // 2. The bag, and its replay.
  const std::vector<srd::SerialChunk> chunks = serial_raw.since(0);
  ASSERT_EQ(live_diagnostics.latest("wire capture").number("chunks published"), chunks.size());
  const std::string bag_path = "/tmp/srd_replay_" + std::to_string(::getpid()) + ".bag";
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    for (const auto& chunk : chunks) bag.write("/live/serial_raw", chunk.header.stamp, chunk);
  }
  ros::param::set("/replayed/driver_node/replay_bag", bag_path);
  const std::string driver = test_support::findDriverNode();
  ASSERT_FALSE(driver.empty());
  test_support::ChildProcess replayer(driver, {"__name:=driver_node", "__ns:=/replayed"});
  const std::optional<int> status = replayer.waitExit(120.0);
  std::remove(bag_path.c_str());
  ASSERT_TRUE(status.has_value()) << "the replay did not end by itself\n" << replayer.output();
  ASSERT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << replayer.output();
  ros::WallDuration(0.5).sleep();  // the last callbacks of this process

  // 3. Message by message, then the counters.
  joint_states.expectEqual();
  imu.expectEqual();
  telemetry.expectEqual();
  foot_pressure.expectEqual();
  battery.expectEqual();

  const DiagnosticsWatch::Status replayed_port = replayed_diagnostics.latest("port " + port);
  for (const auto& [key, value] : live_port.values) {
    if (key.rfind("frames in: ", 0) != 0) continue;
    EXPECT_EQ(replayed_port.value(key), value) << key;
  }
  for (const char* key : {"connects", "bytes in", "checksum errors", "bad tails", "bad lengths",
                          "bytes skipped (resync)"}) {
    EXPECT_EQ(replayed_port.value(key), live_port.value(key)) << key;
  }
  const DiagnosticsWatch::Status replayed_body = replayed_diagnostics.latest("body");
  for (const char* key : {"frames decoded", "decode errors", "last decode error"}) {
    EXPECT_EQ(replayed_body.value(key), live_body.value(key)) << key;
  }
  const DiagnosticsWatch::Status replayed_base = replayed_diagnostics.latest("base");
  for (const char* key :
       {"battery replies", "bad replies", "unknown replies", "FF timeout errors received"}) {
    EXPECT_EQ(replayed_base.value(key), live_base.value(key)) << key;
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_replay");
  return RUN_ALL_TESTS();
}
