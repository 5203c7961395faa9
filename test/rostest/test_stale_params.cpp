// Each launch file that starts the driver clears its private namespace first (clear_params), so
// what an earlier launch left on a roscore that outlived it does not count. The test leaves a
// ~replay_bag (which would make the driver replay a bag, or die on a missing one, instead of
// driving the robot), a disabled base and an unknown key, then starts the launch file with
// roslaunch on this master and checks that the leftovers are gone and that the driver drives the
// simulated base (odom flows, which it does only with the base enabled and the real port open).
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include <csignal>
#include <memory>
#include <string>
#include <vector>

#include "support/process_support.h"
#include "support/ros_test_support.h"

namespace {

constexpr char kNode[] = "/driver_node";

void leaveStaleParameters() {
  ros::param::set(std::string(kNode) + "/replay_bag", "/tmp/srd_stale_params_no_such.bag");
  ros::param::set(std::string(kNode) + "/base/enabled", false);
  ros::param::set(std::string(kNode) + "/left_over_by_a_bench_run", 1);
}

class StaleParams : public testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(ros::param::get("~link", link_)) << "missing test parameter ~link";
    ASSERT_TRUE(ros::param::get("~config", config_)) << "missing test parameter ~config";
    test_support::removeStaleLink(link_);
  }

  void TearDown() override {
    stop(launch_);
    stop(sim_);
    test_support::removeStaleLink(link_);
  }

  /// robot_sim on link_, for driver.launch (sim.launch starts its own).
  void startSimulator() {
    sim_ = std::make_unique<test_support::ChildProcess>(
        "rosrun", std::vector<std::string>{"serial_robot_driver", "robot_sim", "--link", link_});
    ASSERT_TRUE(sim_->started());
  }

  void roslaunch(const std::vector<std::string>& args) {
    std::vector<std::string> all{"serial_robot_driver"};
    all.insert(all.end(), args.begin(), args.end());
    launch_ = std::make_unique<test_support::ChildProcess>("roslaunch", all);
    ASSERT_TRUE(launch_->started());
  }

  /// The leftovers are gone (the launch's file sets none of them) and the driver drives the base on
  /// the real (simulated) port.
  void expectTheLaunchIgnoresTheLeftovers() {
    ros::NodeHandle nh;
    test_support::TopicCounter<nav_msgs::Odometry> odom(nh, "/odom", 1);
    const bool driving = odom.waitForCount(3, 90.0);
    EXPECT_TRUE(driving) << "no odom: the driver does not drive the base; roslaunch said:\n"
                         << (launch_ ? launch_->output() : "");
    EXPECT_FALSE(ros::param::has(std::string(kNode) + "/replay_bag"));
    EXPECT_FALSE(ros::param::has(std::string(kNode) + "/left_over_by_a_bench_run"));
    EXPECT_FALSE(ros::param::has(std::string(kNode) + "/base/enabled"));
    EXPECT_TRUE(launch_->running()) << launch_->output();
  }

  static void stop(std::unique_ptr<test_support::ChildProcess>& child) {
    if (!child) return;
    if (child->running()) {
      child->signal(SIGINT);
      child->waitExit(30.0);
    }
    child.reset();  // SIGKILLs the group if it is still there
  }

  std::string link_;
  std::string config_;  // sets neither replay_bag nor base/enabled: the leftovers would decide
  std::unique_ptr<test_support::ChildProcess> sim_;
  std::unique_ptr<test_support::ChildProcess> launch_;
};

TEST_F(StaleParams, DriverLaunchClearsThem) {
  leaveStaleParameters();
  startSimulator();
  roslaunch({"driver.launch", "config:=" + config_, "port:=" + link_, "respawn:=false"});
  expectTheLaunchIgnoresTheLeftovers();
  // A clean shutdown (the robot's end still there) closes the port; it does not lose it.
  launch_->signal(SIGINT);
  ASSERT_TRUE(launch_->waitExit(60.0).has_value());
  const std::string output = launch_->output();
  EXPECT_NE(output.find("shutting down"), std::string::npos) << output;
  EXPECT_EQ(output.find("reopening"), std::string::npos) << output;
}

TEST_F(StaleParams, DriverLaunchInNodeletModeClearsThem) {
  leaveStaleParameters();
  startSimulator();
  roslaunch({"driver.launch", "config:=" + config_, "port:=" + link_, "respawn:=false",
             "nodelet:=true"});
  expectTheLaunchIgnoresTheLeftovers();
}

TEST_F(StaleParams, SimLaunchClearsThem) {
  leaveStaleParameters();
  roslaunch({"sim.launch", "config:=" + config_, "link:=" + link_});
  expectTheLaunchIgnoresTheLeftovers();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_stale_params", 2);
  return RUN_ALL_TESTS();
}
