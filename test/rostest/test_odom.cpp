// driver_node's odometry, tf and e-stop against the simulated AP1 base (sim::RobotSim in this
// process on the node's pty). The simulator integrates the speed frames it applied, once per PID
// period, into its own pose: the reference the node's odom must match (2 % of the distance,
// 0.02 rad), since odom is the commanded motion the base accepted, not a measurement.
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_msgs/Bool.h>
#include <std_srvs/Trigger.h>
#include <tf2_msgs/TFMessage.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"
#include "support/test_helpers.h"

namespace {

namespace sim = serial_robot_driver::sim;
using test_support::waitFor;

constexpr const char* kNode = "/driver_node";

sim::RobotSim* g_robot = nullptr;

double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

double angleBetween(double a, double b) { return std::abs(std::remainder(a - b, 2.0 * M_PI)); }

class OdomTest : public ::testing::Test {
 protected:
  OdomTest()
      : odom_(nh_, "odom", 5), tf_(nh_, "/tf", 5), diagnostics_(nh_, std::string(kNode).substr(1)) {
    cmd_vel_ = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
    e_stop_ = nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true);
  }

  void SetUp() override {
    ASSERT_TRUE(odom_.waitForCount(5, 30)) << "no odom from driver_node";
    ASSERT_TRUE(waitFor([&] { return cmd_vel_.getNumSubscribers() > 0; }, 20));
    ASSERT_TRUE(waitFor([&] { return e_stop_.getNumSubscribers() > 0; }, 20));
  }

  /// Publishes the twist at 20 Hz for `seconds`, then lets the node's cmd_vel timeout stop the
  /// base and waits until the simulated wheels stand still.
  void drive(double linear, double angular, double seconds) {
    geometry_msgs::Twist twist;
    twist.linear.x = linear;
    twist.angular.z = angular;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      cmd_vel_.publish(twist);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    waitStill();
  }

  void waitStill() {
    ASSERT_TRUE(waitFor(
        [] {
          const auto base = serial_robot_driver::devices::base::sim::baseStats(g_robot->stats());
          return base.last_left_speed == 0 && base.last_right_speed == 0;
        },
        10));
    // A few more ticks so the node's odom has integrated up to the stop.
    const uint64_t seen = odom_.count();
    ASSERT_TRUE(odom_.waitForCount(seen + 10, 10));
  }

  bool resetOdometry() {
    std_srvs::Trigger trigger;
    return test_support::callService("base/reset_odometry", trigger) && trigger.response.success;
  }

  ros::NodeHandle nh_;
  test_support::TopicCounter<nav_msgs::Odometry> odom_;
  test_support::TopicCounter<tf2_msgs::TFMessage> tf_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher cmd_vel_;
  ros::Publisher e_stop_;
};

TEST_F(OdomTest, PoseAfterADriveMatchesTheFramesTheBaseApplied) {
  waitStill();
  const serial_robot_driver::devices::base::sim::BaseSimStats start =
      serial_robot_driver::devices::base::sim::baseStats(g_robot->stats());
  const auto before = odom_.last();
  ASSERT_TRUE(before.has_value());

  drive(0.3, 0.3, 3.0);  // an arc: about 0.9 m and 0.9 rad
  const serial_robot_driver::devices::base::sim::BaseSimStats end =
      serial_robot_driver::devices::base::sim::baseStats(g_robot->stats());
  const auto after = odom_.last();
  ASSERT_TRUE(after.has_value());

  // Both poses as a motion relative to their own start, in the start's frame.
  const auto relative = [](double x0, double y0, double yaw0, double x1, double y1) {
    const double dx = x1 - x0, dy = y1 - y0;
    return std::make_pair(std::cos(yaw0) * dx + std::sin(yaw0) * dy,
                          -std::sin(yaw0) * dx + std::cos(yaw0) * dy);
  };
  const auto sim_move = relative(start.x_m, start.y_m, start.yaw_rad, end.x_m, end.y_m);
  const double odom_yaw0 = yawOf(before->pose.pose.orientation);
  const auto odom_move =
      relative(before->pose.pose.position.x, before->pose.pose.position.y, odom_yaw0,
               after->pose.pose.position.x, after->pose.pose.position.y);
  const double sim_turn = std::remainder(end.yaw_rad - start.yaw_rad, 2 * M_PI);
  const double odom_turn =
      std::remainder(yawOf(after->pose.pose.orientation) - odom_yaw0, 2 * M_PI);
  const double distance = std::hypot(sim_move.first, sim_move.second);
  ASSERT_GT(distance, 0.5) << "the simulated base hardly moved";
  const double error =
      std::hypot(odom_move.first - sim_move.first, odom_move.second - sim_move.second);
  std::printf(
      "odom vs simulated base: distance %.4f m, position error %.4f m (%.2f %%), yaw error %.4f "
      "rad\n",
      distance, error, 100.0 * error / distance, angleBetween(odom_turn, sim_turn));
  EXPECT_LE(error, 0.02 * distance)
      << "sim moved (" << sim_move.first << ", " << sim_move.second << "), odom ("
      << odom_move.first << ", " << odom_move.second << ")";
  EXPECT_LE(angleBetween(odom_turn, sim_turn), 0.02) << "sim " << sim_turn << " odom " << odom_turn;
  EXPECT_GT(std::abs(sim_turn), 0.5);

  // The message itself: frames, a positive covariance grown with the distance, and a still twist.
  EXPECT_EQ(after->header.frame_id, "odom");
  EXPECT_EQ(after->child_frame_id, "base_link");
  EXPECT_GT(after->pose.covariance[0], before->pose.covariance[0]);
  EXPECT_GT(after->pose.covariance[35], before->pose.covariance[35]);
  for (int i = 0; i < 6; ++i) EXPECT_GT(after->pose.covariance[i * 7], 0.0) << "diagonal " << i;
  EXPECT_NEAR(after->twist.twist.linear.x, 0.0, 1e-9);

  // tf carries the same pose, odom -> base_link.
  const auto tf = tf_.last();
  ASSERT_TRUE(tf.has_value());
  ASSERT_FALSE(tf->transforms.empty());
  EXPECT_EQ(tf->transforms[0].header.frame_id, "odom");
  EXPECT_EQ(tf->transforms[0].child_frame_id, "base_link");
  EXPECT_NEAR(tf->transforms[0].transform.translation.x, after->pose.pose.position.x, 1e-9);
  EXPECT_NEAR(tf->transforms[0].transform.translation.y, after->pose.pose.position.y, 1e-9);
}

TEST_F(OdomTest, ResetOdometryPutsThePoseBackToZero) {
  drive(0.2, 0.0, 1.0);
  ASSERT_TRUE(resetOdometry());
  const uint64_t seen = odom_.count();
  ASSERT_TRUE(odom_.waitForCount(seen + 3, 10));
  const auto odom = odom_.last();
  ASSERT_TRUE(odom.has_value());
  EXPECT_NEAR(odom->pose.pose.position.x, 0.0, 1e-9);
  EXPECT_NEAR(odom->pose.pose.position.y, 0.0, 1e-9);
  EXPECT_NEAR(yawOf(odom->pose.pose.orientation), 0.0, 1e-9);
}

TEST_F(OdomTest, LatchedEStopHoldsTheBaseUntilReleased) {
  waitStill();
  // A latched publisher that publishes before the node has even connected: the node must still
  // get the message (on connection).
  ros::Publisher latched = nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true);
  std_msgs::Bool stop;
  stop.data = true;
  latched.publish(stop);
  ASSERT_TRUE(waitFor([&] { return diagnostics_.latest("base").flag("e-stop engaged"); }, 10));
  EXPECT_EQ(diagnostics_.latest("base").level, 1) << "WARN while the e-stop holds the base";

  const uint64_t frames_before =
      serial_robot_driver::devices::base::sim::baseStats(g_robot->stats()).speed_frames_applied;
  const double x_before = serial_robot_driver::devices::base::sim::baseStats(g_robot->stats()).x_m;
  geometry_msgs::Twist twist;
  twist.linear.x = 0.3;
  for (int i = 0; i < 20; ++i) {  // 1 s of cmd_vel that must be ignored
    cmd_vel_.publish(twist);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto base = serial_robot_driver::devices::base::sim::baseStats(g_robot->stats());
    ASSERT_EQ(base.last_left_speed, 0);
    ASSERT_EQ(base.last_right_speed, 0);
  }
  EXPECT_GT(
      serial_robot_driver::devices::base::sim::baseStats(g_robot->stats()).speed_frames_applied,
      frames_before + 20)
      << "speed frames (the heartbeat) keep flowing during the e-stop";
  EXPECT_EQ(serial_robot_driver::devices::base::sim::baseStats(g_robot->stats()).x_m, x_before);
  EXPECT_EQ(serial_robot_driver::devices::base::sim::baseStats(g_robot->stats()).timeouts, 0u);
  ASSERT_TRUE(waitFor(
      [&] { return diagnostics_.latest("base").number("cmd_vel ignored (e-stop)") >= 10; }, 10));

  stop.data = false;
  latched.publish(stop);
  ASSERT_TRUE(waitFor([&] { return !diagnostics_.latest("base").flag("e-stop engaged"); }, 10));
  cmd_vel_.publish(twist);
  EXPECT_TRUE(waitFor(
      [] {
        return serial_robot_driver::devices::base::sim::baseStats(g_robot->stats())
                   .last_left_speed > 0;
      },
      10))
      << "cmd_vel obeyed again after the release";
  waitStill();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_odom");
  sim::SimOptions options;
  options.link = test_support::nodeParam(kNode, "port");
  options.device("body").enabled = false;
  options.device("servo_bus").enabled = false;
  return test_support::runAllTestsWithSim(options, &g_robot);
}
