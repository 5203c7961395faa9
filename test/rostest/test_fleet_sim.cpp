// Two robots on one master (fleet_sim.test, launch/fleet_sim.launch): namespaces keep commands,
// services, e_stop and states apart; tf_prefix keeps their frames apart; /diagnostics names them.
#include <diagnostic_aggregator/aggregator.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <urdf/model.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>
#include <string>

#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/WheelCommand.h"
#include "support/ros_test_support.h"

namespace {

using test_support::DiagnosticsWatch;
using test_support::TopicCounter;
using test_support::waitFor;

const std::vector<std::string> kRobots = {"robot1", "robot2"};

/// Every frame named in /tf by one node (header and child frames).
class TfFramesOf {
 public:
  TfFramesOf(ros::NodeHandle& nh, const std::string& node) : node_(node) {
    // A MessageEvent callback (not a message one) carries the publisher's name.
    sub_ = nh.subscribe("/tf", 100, &TfFramesOf::onTf, this);
  }
  // onTf runs on the spinner thread until the subscription ends, and the mutex and set it uses die
  // before sub_ would: shutdown() waits for a running callback.
  ~TfFramesOf() { sub_.shutdown(); }
  TfFramesOf(const TfFramesOf&) = delete;
  TfFramesOf& operator=(const TfFramesOf&) = delete;
  std::set<std::string> frames() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }

 private:
  void onTf(const ros::MessageEvent<tf2_msgs::TFMessage const>& event) {
    if (event.getPublisherName() != node_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& t : event.getMessage()->transforms) {
      frames_.insert(t.header.frame_id);
      frames_.insert(t.child_frame_id);
    }
  }

  const std::string node_;
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::set<std::string> frames_;
};

TEST(Fleet, EveryFrameEachDriverPublishesIsUnderItsPrefix) {
  ros::NodeHandle nh;
  for (const std::string& robot : kRobots) {
    SCOPED_TRACE(robot);
    TopicCounter<nav_msgs::Odometry> odom(nh, "/" + robot + "/odom", 1);
    TopicCounter<sensor_msgs::Imu> imu(nh, "/" + robot + "/imu/data", 1);
    TopicCounter<sensor_msgs::JointState> wheels(nh, "/" + robot + "/wheel_states", 1);
    TfFramesOf tf(nh, "/" + robot + "/driver_node");
    ASSERT_TRUE(odom.waitForCount(3, 60.0));
    ASSERT_TRUE(imu.waitForCount(3, 60.0));
    ASSERT_TRUE(wheels.waitForCount(3, 60.0));
    ASSERT_TRUE(waitFor([&] { return tf.frames().size() >= 2; }, 30.0));
    EXPECT_EQ(odom.last()->header.frame_id, robot + "/odom");
    EXPECT_EQ(odom.last()->child_frame_id, robot + "/base_link");
    EXPECT_EQ(imu.last()->header.frame_id, robot + "/imu_link");
    EXPECT_EQ(wheels.last()->header.frame_id, robot + "/base_link");
    for (const std::string& frame : tf.frames()) {
      EXPECT_EQ(frame.rfind(robot + "/", 0), 0u) << frame << " on /tf from " << robot;
    }
  }
}

TEST(Fleet, DiagnosticsNameEachDriver) {
  ros::NodeHandle nh;
  DiagnosticsWatch robot1(nh, "robot1/driver_node");
  DiagnosticsWatch robot2(nh, "robot2/driver_node");
  EXPECT_TRUE(waitFor([&] { return robot1.latest("base").received > 0; }, 30.0));
  EXPECT_TRUE(waitFor([&] { return robot2.latest("base").received > 0; }, 30.0));
}

TEST(Fleet, FleetAnalyzersGroupTheStatusesByRobot) {
  ros::NodeHandle nh;
  diagnostic_aggregator::Aggregator aggregator;  // config/fleet_analyzers.yaml from ~analyzers
  std::mutex mutex;
  std::vector<std::string> names;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics_agg", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        names.clear();
        for (const auto& status : array->status) names.push_back(status.name);
      });
  const auto has = [&](const std::string& name) {
    std::lock_guard<std::mutex> lock(mutex);
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  EXPECT_TRUE(waitFor(
      [&] {
        aggregator.publishData();
        ros::Duration(0.5).sleep();
        return has("/Robot 1/base") && has("/Robot 2/base") && has("/Robot 1/servo_bus") &&
               has("/Robot 2/body");
      },
      60.0));
  std::lock_guard<std::mutex> lock(mutex);
  for (const std::string& name : names) {
    EXPECT_FALSE(name.rfind("/Other/", 0) == 0 && name.find("driver_node") != std::string::npos)
        << name << " is in no robot's group";
  }
}

TEST(Fleet, CmdVelAndEStopStayWithTheirRobot) {
  ros::NodeHandle nh;
  TopicCounter<serial_robot_driver::WheelCommand> wheels1(nh, "/robot1/wheel_command", 1);
  TopicCounter<serial_robot_driver::WheelCommand> wheels2(nh, "/robot2/wheel_command", 1);
  ros::Publisher cmd1 = nh.advertise<geometry_msgs::Twist>("/robot1/cmd_vel", 10);
  ros::Publisher cmd2 = nh.advertise<geometry_msgs::Twist>("/robot2/cmd_vel", 10);
  ros::Publisher stop1 = nh.advertise<std_msgs::Bool>("/robot1/e_stop", 1, true);
  ASSERT_TRUE(waitFor([&] { return cmd1.getNumSubscribers() > 0 && cmd2.getNumSubscribers() > 0; }, 30.0));
  ASSERT_TRUE(wheels1.waitForCount(1, 30.0) && wheels2.waitForCount(1, 30.0));
  geometry_msgs::Twist forward;
  forward.linear.x = 0.2;
  const auto moving = [](const auto& counter) {
    const auto last = counter.last();
    return last && last->left_ticks > 0 && last->right_ticks > 0;
  };

  // robot1 drives; robot2 is not told to and stays put.
  ASSERT_TRUE(waitFor([&] { cmd1.publish(forward); return moving(wheels1); }, 30.0));
  for (int i = 0; i < 10; ++i) {
    cmd1.publish(forward);
    ros::Duration(0.05).sleep();
    EXPECT_FALSE(moving(wheels2)) << "robot2 moves on robot1's cmd_vel";
  }

  // robot1's e_stop stops robot1 only: robot2 still obeys its cmd_vel.
  std_msgs::Bool engaged;
  engaged.data = true;
  stop1.publish(engaged);
  EXPECT_TRUE(waitFor([&] { cmd1.publish(forward); return !moving(wheels1); }, 30.0));
  EXPECT_TRUE(waitFor([&] { cmd2.publish(forward); return moving(wheels2); }, 30.0))
      << "robot2 stopped by robot1's e_stop";
  cmd1.publish(forward);
  ros::Duration(0.3).sleep();
  EXPECT_FALSE(moving(wheels1)) << "robot1 moved during its e_stop";
  engaged.data = false;
  stop1.publish(engaged);
  EXPECT_TRUE(waitFor([&] { cmd1.publish(forward); return moving(wheels1); }, 30.0));
}

TEST(Fleet, JointCommandsAndJointStatesStayWithTheirRobot) {
  ros::NodeHandle nh;
  TopicCounter<sensor_msgs::JointState> joints1(nh, "/robot1/joint_states", 1);
  TopicCounter<sensor_msgs::JointState> joints2(nh, "/robot2/joint_states", 1);
  ros::Publisher commands1 = nh.advertise<sensor_msgs::JointState>("/robot1/joint_commands", 10);
  ASSERT_TRUE(waitFor([&] { return commands1.getNumSubscribers() > 0; }, 30.0));
  ASSERT_TRUE(joints2.waitForCount(1, 30.0));
  const double robot2_before = joints2.last()->position.at(0);
  sensor_msgs::JointState command;
  command.name = {"joint_1", "joint_2"};
  command.position = {robot2_before + 0.5, 0.0};
  EXPECT_TRUE(waitFor(
      [&] {
        commands1.publish(command);
        const auto last = joints1.last();
        return last && std::abs(last->position.at(0) - command.position[0]) < 0.01;
      },
      30.0));
  ros::Duration(0.3).sleep();
  EXPECT_NEAR(joints2.last()->position.at(0), robot2_before, 0.01) << "robot2's joint followed robot1's command";
}

TEST(Fleet, ServoCallsReachTheirOwnRobotsBus) {
  ros::NodeHandle nh;
  const auto readAngle = [](const std::string& robot, double* angle) {
    serial_robot_driver::ServoReadAngle read;
    read.request.id = 1;
    if (!test_support::callService("/" + robot + "/servo/read_angle", read) ||
        !read.response.success)
      return false;
    *angle = read.response.angle_deg;
    return true;
  };
  ASSERT_TRUE(ros::service::waitForService("/robot1/servo/rotate", ros::Duration(30)));
  ASSERT_TRUE(ros::service::waitForService("/robot2/servo/read_angle", ros::Duration(30)));
  double robot2_before = 0;
  ASSERT_TRUE(readAngle("robot2", &robot2_before));
  serial_robot_driver::ServoRotate rotate;
  rotate.request.id = 1;
  rotate.request.angle_deg = robot2_before > 0 ? robot2_before - 60.0 : robot2_before + 60.0;
  rotate.request.interval_ms = 0;
  ASSERT_TRUE(test_support::callService("/robot1/servo/rotate", rotate));
  ASSERT_TRUE(rotate.response.success) << rotate.response.message;
  double robot1_angle = 0;
  EXPECT_TRUE(waitFor(
      [&] {
        return readAngle("robot1", &robot1_angle) &&
               std::abs(robot1_angle - rotate.request.angle_deg) < 1.0;
      },
      30.0))
      << "robot1's servo 1 is at " << robot1_angle;
  double robot2_after = 0;
  ASSERT_TRUE(readAngle("robot2", &robot2_after));
  EXPECT_NEAR(robot2_after, robot2_before, 1.0) << "robot2's servo moved on robot1's call";
}

TEST(Fleet, EveryLinkReachesItsRobotsOdomAndEachOdomTheMap) {
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  for (const std::string& robot : kRobots) {
    SCOPED_TRACE(robot);
    std::string xml;
    ASSERT_TRUE(waitFor([&] { return ros::param::get("/" + robot + "/robot_description", xml); }, 30.0));
    urdf::Model model;
    ASSERT_TRUE(model.initString(xml));
    ASSERT_GE(model.links_.size(), 6u);
    for (const auto& [name, link] : model.links_) {
      std::string error;
      EXPECT_TRUE(buffer.canTransform(robot + "/odom", robot + "/" + name, ros::Time(0),
                                      ros::Duration(30.0), &error))
          << name << ": " << error;
    }
    std::string error;
    EXPECT_TRUE(buffer.canTransform("map", robot + "/odom", ros::Time(0), ros::Duration(30.0), &error))
        << error;
  }
  // Apart in the map: their odom origins do not coincide.
  const auto between = buffer.lookupTransform("robot1/odom", "robot2/odom", ros::Time(0));
  EXPECT_GT(std::hypot(between.transform.translation.x, between.transform.translation.y), 0.5);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_fleet_sim");
  return RUN_ALL_TESTS();
}
