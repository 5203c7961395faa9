// driver_node with ~ros2/enabled, seen from both graphs at once: a ROS 1 subscriber and a second
// DDS participant (ros2_peer.h). One frame gets one stamp on both; the one e-stop set from either
// graph stops a base that the other graph drives; the ROS 2 node is named like the ROS 1 node.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <sensor_msgs/JointState.h>
#include <serial_robot_driver/WheelCommand.h>
#include <std_msgs/Bool.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <cstring>
#include <limits>
#include <set>
#include <utility>

#include "dds_front/hostile_dds_inputs.h"
#include "dds_front/ros2_peer.h"
#include "serial_robot_driver/dds/messages.h"
#include "support/ros_test_support.h"

namespace {

int g_domain = 231;

TEST(Ros2Graph, AFrameHasTheSameStampOnBothGraphs) {
  ros::NodeHandle nh;
  test_support::TopicCounter<sensor_msgs::JointState> ros1(nh, "joint_states", 500);
  dds_test::Ros2Peer peer(g_domain);
  const dds_entity_t ros2 = peer.reader(sensor_msgs_msg_dds__JointState__desc, "rt/joint_states");
  ASSERT_TRUE(ros1.waitForCount(1, 30.0));
  EXPECT_TRUE(dds_test::waitForSample<sensor_msgs_msg_dds__JointState_>(ros2, [&](const auto& s) {
    for (const sensor_msgs::JointState& msg : ros1.since(0)) {
      if (msg.header.stamp.sec == static_cast<uint32_t>(s.header.stamp.sec) &&
          msg.header.stamp.nsec == s.header.stamp.nanosec && s.position._length == 2 &&
          msg.position.size() == 2 && msg.position[0] == s.position._buffer[0]) {
        return true;
      }
    }
    return false;
  }));
}

/// Waits until `frames` more wheel frames all went out with the wheels stopped (or all moving).
bool wheelsHold(const test_support::TopicCounter<serial_robot_driver::WheelCommand>& frames,
                bool moving) {
  uint64_t from = frames.count();
  return dds_test::waitFor([&] {
    const std::vector<serial_robot_driver::WheelCommand> since = frames.since(from);
    for (std::size_t i = 0; i < since.size(); ++i) {
      if ((since[i].left_ticks != 0) != moving) {
        from += i + 1;  // a frame of the other kind: count again from the next one
        return false;
      }
    }
    return since.size() >= 25;
  });
}

TEST(Ros2Graph, OneEStopForBothGraphs) {
  ros::NodeHandle nh;
  test_support::TopicCounter<serial_robot_driver::WheelCommand> frames(nh, "wheel_command", 200);
  ros::Publisher ros1_e_stop = nh.advertise<std_msgs::Bool>("e_stop", 1, true);
  dds_test::Ros2Peer peer(g_domain);
  const dds_entity_t cmd_vel = peer.writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  const dds_entity_t ros2_e_stop = peer.writer(std_msgs_msg_dds__Bool__desc, "rt/e_stop");
  ASSERT_TRUE(dds_test::waitFor([&] {
    return dds_test::Ros2Peer::matched(cmd_vel) && dds_test::Ros2Peer::matched(ros2_e_stop);
  }));
  ASSERT_TRUE(frames.waitConnected(30.0));
  const dds_test::TwistStream driving(cmd_vel, 0.2);
  EXPECT_TRUE(wheelsHold(frames, true)) << "cmd_vel from ROS 2 drives the base";
  std_msgs::Bool engaged;
  engaged.data = true;
  ros1_e_stop.publish(engaged);
  EXPECT_TRUE(wheelsHold(frames, false)) << "the ROS 1 e_stop stops what ROS 2 drives";
  ASSERT_TRUE(dds_test::writeBool(ros2_e_stop, false));
  EXPECT_TRUE(wheelsHold(frames, true)) << "released from ROS 2: its cmd_vel moves it again";
}

/// `key`'s value in the ROS 1 graph's "driver_node: e_stop" status ("" when absent).
std::string ros1EStopValue(const diagnostic_msgs::DiagnosticArray& array, const std::string& key) {
  for (const auto& status : array.status) {
    if (status.name != "driver_node: e_stop") continue;
    for (const auto& value : status.values) {
      if (value.key == key) return value.value;
    }
  }
  return "";
}

TEST(Ros2Graph, BothGraphsReportOneCountOfRefusedInputs) {
  ros::NodeHandle nh;
  test_support::TopicCounter<diagnostic_msgs::DiagnosticArray> ros1_diagnostics(nh, "/diagnostics",
                                                                                20);
  ros::Publisher ros1_trajectories =
      nh.advertise<trajectory_msgs::JointTrajectory>("joint_trajectory", 10);
  dds_test::Ros2Peer peer(g_domain);
  dds_test::EStopStatus ros2_status(peer);
  const dds_entity_t ros2_trajectories =
      peer.writer(trajectory_msgs_msg_dds__JointTrajectory__desc, "rt/joint_trajectory");
  ASSERT_TRUE(dds_test::waitFor([&] {
    return dds_test::Ros2Peer::matched(ros2_trajectories) &&
           ros1_trajectories.getNumSubscribers() > 0;
  }));
  const std::string key = "inputs refused: joint_trajectory";
  const uint64_t before = ros2_status.count(key);
  // One trajectory with a NaN from each graph.
  trajectory_msgs::JointTrajectory ros1_bad;
  ros1_bad.joint_names = {"joint_1"};
  ros1_bad.points.resize(1);
  ros1_bad.points[0].positions = {std::numeric_limits<double>::quiet_NaN()};
  ros1_bad.points[0].time_from_start = ros::Duration(1.0);
  ros1_trajectories.publish(ros1_bad);
  ASSERT_EQ(dds_test::nanTrajectory({"joint_1"}).write(ros2_trajectories), DDS_RETCODE_OK);
  const std::string expected = std::to_string(before + 2);
  EXPECT_TRUE(ros2_status.waitForCount(key, before + 2)) << ros2_status.count(key);
  EXPECT_TRUE(dds_test::waitFor([&] {
    const auto last = ros1_diagnostics.last();
    return last && ros1EStopValue(*last, key) == expected;
  })) << "ROS 1 reports "
      << (ros1_diagnostics.last() ? ros1EStopValue(*ros1_diagnostics.last(), key) : "nothing")
      << ", ROS 2 " << ros2_status.count(key) << ": one count, whichever graph refused";
}

TEST(Ros2Graph, HostileRos2InputMovesNothingAndBothGraphsGoOn) {
  ros::NodeHandle nh;
  test_support::TopicCounter<serial_robot_driver::WheelCommand> frames(nh, "wheel_command", 200);
  test_support::TopicCounter<sensor_msgs::JointState> joint_states(nh, "joint_states", 1);
  dds_test::Ros2Peer peer(g_domain);
  const dds_entity_t cmd_vel = peer.writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  const dds_entity_t commands =
      peer.writer(sensor_msgs_msg_dds__JointState__desc, "rt/joint_commands");
  std::vector<dds_entity_t> raw;
  for (const dds_test::MalformedInput& input : dds_test::malformedInputs()) {
    raw.push_back(peer.rawWriter(input.dds_type, input.topic));
  }
  ASSERT_TRUE(dds_test::waitFor([&] {
    for (dds_entity_t writer : raw) {
      if (!dds_test::Ros2Peer::matched(writer)) return false;
    }
    return dds_test::Ros2Peer::matched(cmd_vel) && dds_test::Ros2Peer::matched(commands);
  }));
  ASSERT_TRUE(frames.waitConnected(30.0));
  for (const auto& sample : dds_test::hostileTwists(false)) ASSERT_EQ(sample.write(cmd_vel), 0);
  for (const auto& sample : dds_test::hostileJointCommands({"joint_1", "joint_2"})) {
    ASSERT_EQ(sample.write(commands), 0) << sample.what;
  }
  const std::vector<dds_test::MalformedInput> malformed = dds_test::malformedInputs();
  for (std::size_t i = 0; i < malformed.size(); ++i) {
    for (const auto& payload : malformed[i].payloads) dds_test::writeRaw(raw[i], payload);
  }
  EXPECT_TRUE(wheelsHold(frames, false)) << "nothing of it moved the base";
  const uint64_t states = joint_states.count();
  EXPECT_TRUE(joint_states.waitForCount(states + 10, 30.0)) << "the ROS 1 graph goes on";
  const dds_entity_t e_stop = peer.writer(std_msgs_msg_dds__Bool__desc, "rt/e_stop");
  ASSERT_TRUE(dds_test::waitFor([&] { return dds_test::Ros2Peer::matched(e_stop); }));
  ASSERT_TRUE(dds_test::writeBool(e_stop, false));  // a malformed Bool may have engaged it
  const dds_test::TwistStream driving(cmd_vel, 0.2);
  EXPECT_TRUE(wheelsHold(frames, true)) << "a valid cmd_vel afterwards drives the base";
}

TEST(Ros2Graph, TheRos2NodeHasTheRos1NodesName) {
  dds_test::Ros2Peer peer(g_domain);
  const dds_entity_t reader = peer.reader(rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                          "ros_discovery_info", DDS_DURABILITY_TRANSIENT_LOCAL);
  EXPECT_TRUE(dds_test::waitForSample<rmw_dds_common_msg_dds__ParticipantEntitiesInfo_>(
      reader, [](const auto& info) {
        for (uint32_t i = 0; i < info.node_entities_info_seq._length; ++i) {
          const auto& node = info.node_entities_info_seq._buffer[i];
          if (std::strcmp(node.node_name, "driver_node") == 0 &&
              std::strcmp(node.node_namespace, "/") == 0) {
            return true;
          }
        }
        return false;
      }));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_ros2_graph");
  ros::NodeHandle("~").param("domain_id", g_domain, g_domain);
  return RUN_ALL_TESTS();
}
