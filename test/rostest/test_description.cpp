// description.launch next to sim.launch (description.test): every link of robot_description has a
// transform to odom, and wheel_states turns the wheels by the distance odom drives.
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <urdf/model.h>

#include <cmath>
#include <map>
#include <string>
#include <thread>

#include "support/ros_test_support.h"

namespace {

using test_support::TopicCounter;
using test_support::waitFor;

/// Every link of the robot_description parameter in `ns` (e.g. "" or "/robot1/").
std::vector<std::string> descriptionLinks(const std::string& ns) {
  std::string xml;
  EXPECT_TRUE(waitFor([&] { return ros::param::get(ns + "robot_description", xml); }, 30.0));
  urdf::Model model;
  EXPECT_TRUE(model.initString(xml));
  std::vector<std::string> links;
  for (const auto& [name, link] : model.links_) links.push_back(name);
  return links;
}

TEST(Description, EveryLinkHasATransformToOdom) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const std::vector<std::string> links = descriptionLinks("");
  ASSERT_GE(links.size(), 6u) << "base, two wheels, imu and the two body joints' links";
  for (const std::string& link : links) {
    std::string error;
    EXPECT_TRUE(buffer.canTransform("odom", link, ros::Time(0), ros::Duration(30.0), &error))
        << link << ": " << error;
  }
  const auto imu = buffer.lookupTransform("base_link", "imu_link", ros::Time(0));
  EXPECT_NEAR(imu.transform.translation.z, 0.19, 1e-9) << "the launch's imu_xyz";
}

/// The angle of `child` about y in `parent` (the servo arms' and wheels' axis).
double pitchOf(const tf2_ros::Buffer& buffer, const std::string& parent, const std::string& child) {
  const auto t = buffer.lookupTransform(parent, child, ros::Time(0)).transform.rotation;
  // Rotation about y only: q = (0, sin(a/2), 0, cos(a/2)).
  return 2.0 * std::atan2(t.y, t.w);
}

TEST(Description, TfFollowsTheDriversJointStates) {
  ros::NodeHandle nh;
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  TopicCounter<sensor_msgs::JointState> joints(nh, "joint_states", 1);
  ros::Publisher commands = nh.advertise<sensor_msgs::JointState>("joint_commands", 10);
  ASSERT_TRUE(waitFor([&] { return commands.getNumSubscribers() > 0; }, 30.0));
  sensor_msgs::JointState command;
  command.name = {"joint_1", "joint_2"};
  command.position = {0.6, -0.4};
  // The simulated servos move there; the description's arms must follow what joint_states says.
  EXPECT_TRUE(waitFor(
      [&] {
        commands.publish(command);
        const auto last = joints.last();
        if (!last || last->position.size() != 2 || std::abs(last->position[0] - 0.6) > 0.01) return false;
        try {
          return std::abs(pitchOf(buffer, "base_link", "joint_1_link") - last->position[0]) < 0.01 &&
                 std::abs(pitchOf(buffer, "base_link", "joint_2_link") - last->position[1]) < 0.01;
        } catch (const tf2::TransformException&) {
          return false;
        }
      },
      60.0))
      << "joint_1_link / joint_2_link on tf do not follow joint_states";
}

TEST(Description, WheelStatesTurnByTheDistanceOdomDrives) {
  ros::NodeHandle nh;
  // Every message of both, to pair them by stamp: the driver stamps a tick's odom and
  // wheel_states alike.
  TopicCounter<nav_msgs::Odometry> odom(nh, "odom");
  TopicCounter<sensor_msgs::JointState> wheels(nh, "wheel_states");
  ASSERT_TRUE(odom.waitForCount(5, 30.0));
  ASSERT_TRUE(wheels.waitForCount(5, 30.0));
  double radius = 0;
  ASSERT_TRUE(ros::param::get(std::string("/driver_node/base/wheel_diameter"), radius));
  radius /= 2.0;

  const double speed = 0.2;
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  ASSERT_TRUE(waitFor([&] { return cmd_vel.getNumSubscribers() > 0; }, 30.0));
  const uint64_t odom_before = odom.count();
  geometry_msgs::Twist forward;
  forward.linear.x = speed;
  // Straight ahead, until odom has moved 0.2 m.
  ASSERT_TRUE(waitFor(
      [&] {
        cmd_vel.publish(forward);
        const auto last = odom.last();
        return last && last->pose.pose.position.x > 0.2;
      },
      60.0));
  const auto moving_odom = odom.since(odom_before);
  const auto all_wheels = wheels.since(0);
  std::map<ros::Time, sensor_msgs::JointState> by_stamp;
  for (const auto& w : all_wheels) by_stamp[w.header.stamp] = w;

  int paired = 0, moving = 0;
  for (const auto& o : moving_odom) {
    const auto it = by_stamp.find(o.header.stamp);
    if (it == by_stamp.end()) continue;
    const sensor_msgs::JointState& w = it->second;
    ASSERT_EQ(w.name, (std::vector<std::string>{"left_wheel_joint", "right_wheel_joint"}));
    ASSERT_EQ(w.position.size(), 2u);
    ASSERT_EQ(w.velocity.size(), 2u);
    EXPECT_EQ(w.header.frame_id, "base_link");
    ++paired;
    // Straight: both wheels' paths are the distance driven (the robot started at rest at 0).
    EXPECT_NEAR(w.position[0] * radius, o.pose.pose.position.x, 1e-6);
    EXPECT_NEAR(w.position[1] * radius, o.pose.pose.position.x, 1e-6);
    EXPECT_NEAR(w.velocity[0] * radius, o.twist.twist.linear.x, 1e-6);
    EXPECT_NEAR(w.velocity[1] * radius, o.twist.twist.linear.x, 1e-6);
    if (o.twist.twist.linear.x > 0.9 * speed) ++moving;
  }
  EXPECT_GT(paired, 10);
  EXPECT_GT(moving, 5) << "the wheels turned at the commanded speed";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_description");
  return RUN_ALL_TESTS();
}
