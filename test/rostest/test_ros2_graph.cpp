// driver_node with ~ros2/enabled, seen from both graphs at once: a ROS 1 subscriber and a second
// DDS participant (ros2_peer.h). One frame gets one stamp on both; the one e-stop set from either
// graph stops a base that the other graph drives; the ROS 2 node is named like the ROS 1 node.
#include <gtest/gtest.h>
#include <sensor_msgs/JointState.h>
#include <serial_robot_driver/WheelCommand.h>
#include <std_msgs/Bool.h>

#include <cstring>
#include <set>
#include <utility>

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
