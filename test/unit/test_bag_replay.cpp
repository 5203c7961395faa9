// readRecording() / BagReplay: what a bag must hold to be replayed, and the one clear message for
// each way it can fail (the node prints it and exits non-zero). Bags are written here with the
// rosbag C++ API into a fresh temporary directory.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/ros/bag_replay.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {
namespace {

class BagReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/srd_bag_replay_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    for (const auto& file : files_) std::remove(file.c_str());
    ::rmdir(dir_.c_str());
  }
  std::string file(const std::string& name) {
    files_.push_back(dir_ + "/" + name);
    return files_.back();
  }
  static serial_robot_driver::SerialChunk chunk(const std::string& port, bool outbound,
                                                double stamp, std::vector<uint8_t> data) {
    serial_robot_driver::SerialChunk msg;
    msg.header.stamp = ros::Time(stamp);
    msg.port = port;
    msg.outbound = outbound;
    msg.data = std::move(data);
    return msg;
  }
  static void write(rosbag::Bag& bag, const std::string& topic,
                    const serial_robot_driver::SerialChunk& c) {
    bag.write(topic, c.header.stamp, c);
  }
  /// The message readRecording or BagReplay throws.
  template <typename Call>
  static std::string errorOf(Call call) {
    try {
      call();
    } catch (const ReplayError& e) {
      return e.what();
    }
    return "no error";
  }

  std::string dir_;
  std::vector<std::string> files_;
};

TEST_F(BagReplayTest, ReadsTheInboundChunksPerPortInOrder) {
  const std::string path = file("good.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    write(bag, "/robot/serial_raw", chunk("/dev/ttyA", false, 100.0, {}));
    write(bag, "/robot/serial_raw", chunk("/dev/ttyA", false, 100.5, {0xAA, 0x55}));
    write(bag, "/robot/serial_raw", chunk("/dev/ttyA", true, 100.6, {0x01, 0x02, 0x03}));
    write(bag, "/robot/serial_raw", chunk("/dev/ttyB", false, 100.7, {0x1F}));
    write(bag, "/robot/serial_raw", chunk("/dev/ttyA", false, 101.25, {0x7E}));
  }
  const Recording recording = readRecording(path);
  EXPECT_EQ(recording.topic, "/robot/serial_raw");
  EXPECT_EQ(recording.outbound_chunks, 1u);
  ASSERT_EQ(recording.ports.size(), 2u);
  const auto& a = recording.ports.at("/dev/ttyA");
  ASSERT_EQ(a.size(), 3u);
  EXPECT_TRUE(a[0].data.empty());  // the "port opened" mark
  EXPECT_EQ(a[1].data, (std::vector<uint8_t>{0xAA, 0x55}));
  EXPECT_EQ(a[2].data, (std::vector<uint8_t>{0x7E}));
  EXPECT_EQ(a[2].recorded, std::chrono::nanoseconds(101250000000LL));
  // The bag ends with its last message (of any topic).
  EXPECT_EQ(recording.end, std::chrono::nanoseconds(101250000000LL));
  // The arrival handed to the link lies on the replay's timeline and maps back to the recorded
  // stamp exactly.
  DriverParams replaying;
  replaying.replay_bag = path;
  replaying.replay_timeline =
      std::make_shared<transport::ReplayPacing>(1.0, a[0].recorded, recording.end);
  const auto arrival = replaying.replay_timeline->onTimeline(a[2].recorded);
  EXPECT_EQ(arrival - replaying.replay_timeline->onTimeline(a[0].recorded),
            std::chrono::milliseconds(1250));
  EXPECT_EQ(ArrivalStamps(replaying)(arrival), ros::Time(101.25));
  EXPECT_EQ(recording.ports.at("/dev/ttyB").at(0).data, (std::vector<uint8_t>{0x1F}));
}

TEST_F(BagReplayTest, AMissingBagIsNamed) {
  const std::string path = dir_ + "/nowhere.bag";
  const std::string error = errorOf([&] { readRecording(path); });
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("no such file"), std::string::npos) << error;
}

TEST_F(BagReplayTest, AFileThatIsNoBagIsNamed) {
  const std::string path = file("notes.bag");
  std::ofstream(path) << "these are field notes, not a bag\n";
  const std::string error = errorOf([&] { readRecording(path); });
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("cannot be read as a bag"), std::string::npos) << error;
}

TEST_F(BagReplayTest, ABagWithoutSerialRawListsItsTopics) {
  const std::string path = file("telemetry_only.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    sensor_msgs::JointState joints;
    joints.header.stamp = ros::Time(5.0);
    bag.write("/joint_states", joints.header.stamp, joints);
  }
  const std::string error = errorOf([&] { readRecording(path); });
  EXPECT_NE(error.find("has no serial_raw topic"), std::string::npos) << error;
  EXPECT_NE(error.find("/joint_states"), std::string::npos) << error;
}

TEST_F(BagReplayTest, ABagWithOnlyWritesHasNothingToReplay) {
  const std::string path = file("writes_only.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    write(bag, "/serial_raw", chunk("/dev/ttyA", true, 1.0, {0x01}));
  }
  const std::string error = errorOf([&] { readRecording(path); });
  EXPECT_NE(error.find("no inbound chunk"), std::string::npos) << error;
}

TEST_F(BagReplayTest, SerialRawOfSeveralDriversIsAmbiguous) {
  const std::string path = file("two_robots.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    write(bag, "/robot1/serial_raw", chunk("/dev/ttyA", false, 1.0, {0x01}));
    write(bag, "/robot2/serial_raw", chunk("/dev/ttyA", false, 1.0, {0x01}));
  }
  const std::string error = errorOf([&] { readRecording(path); });
  EXPECT_NE(error.find("/robot1/serial_raw"), std::string::npos) << error;
  EXPECT_NE(error.find("/robot2/serial_raw"), std::string::npos) << error;
}

TEST_F(BagReplayTest, AChunkOfAPortTheConfigurationLacksIsNamed) {
  const std::string path = file("other_port.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    write(bag, "/serial_raw", chunk("/dev/ttyUSB0", false, 1.0, {0x01}));
    write(bag, "/serial_raw", chunk("/dev/ttyACM7", false, 1.1, {0x02}));
  }
  DriverParams params;  // every device on /dev/ttyUSB0
  params.replay_bag = path;
  const std::string error = errorOf([&] { BagReplay replay(params); });
  EXPECT_NE(error.find("port /dev/ttyACM7"), std::string::npos) << error;
  EXPECT_NE(error.find("configuration does not have"), std::string::npos) << error;

  params.section(devices::servo_bus::kServoBusSection).port = "/dev/ttyACM7";  // now it has it
  EXPECT_EQ(errorOf([&] { BagReplay replay(params); }), "no error");
}

TEST(ConfiguredPorts, AreTheEnabledDevicesPaths) {
  DriverParams params;
  params.section(devices::body::kBodySection).port = "/dev/ttyBODY";
  params.section(devices::servo_bus::kServoBusSection).enabled = false;
  params.section(devices::servo_bus::kServoBusSection).port = "/dev/ttySERVO";
  EXPECT_EQ(configuredPorts(params), (std::set<std::string>{"/dev/ttyUSB0", "/dev/ttyBODY"}));
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
