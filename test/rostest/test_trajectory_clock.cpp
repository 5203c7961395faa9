// A step of the ROS clock changes nothing on the wire (trajectory_clock.test): under use_sim_time
// this test publishes /clock, running with steady time, and steps it 100 s forward, then 150 s
// back, while a body goal runs. The sync-writes (read through a test_support::PtyTap in front of
// the simulated board, sim::RobotSim in this process) must go on smoothly: no jump to the end on
// the forward step, no replay on the backward one, and the goal succeeds. Outcomes only: no
// durations.
#include <actionlib/client/simple_action_client.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/JointState.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/pty_tap.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
using serial_robot_driver::FollowJointTrajectoryAction;
using serial_robot_driver::FollowJointTrajectoryGoal;
using Client = actionlib::SimpleActionClient<FollowJointTrajectoryAction>;
using State = actionlib::SimpleClientGoalState;
using Bytes = std::vector<uint8_t>;
using test_support::waitFor;

constexpr const char* kNode = "/driver_node";
constexpr double kWait = 30.0;

sim::RobotSim* g_robot = nullptr;
test_support::PtyTap* g_tap = nullptr;

/// /clock: 1000 s plus the steady time since start plus `offset_s`, every 10 ms.
class ClockPublisher {
 public:
  explicit ClockPublisher(ros::NodeHandle& nh)
      : pub_(nh.advertise<rosgraph_msgs::Clock>("/clock", 10)), start_(Clock::now()) {
    thread_ = std::thread([this] {
      while (running_) {
        rosgraph_msgs::Clock msg;
        msg.clock =
            ros::Time(1000.0 + std::chrono::duration<double>(Clock::now() - start_).count() +
                      offset_s_.load());
        pub_.publish(msg);
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    });
  }
  ~ClockPublisher() {
    running_ = false;
    thread_.join();
  }
  void step(double seconds) { offset_s_ = offset_s_.load() + seconds; }

 private:
  using Clock = std::chrono::steady_clock;
  ros::Publisher pub_;
  const Clock::time_point start_;
  std::atomic<double> offset_s_{0.0};
  std::atomic<bool> running_{true};
  std::thread thread_;
};

ClockPublisher* g_clock = nullptr;

/// joint_1 (servo 2, the first of ~body/servo_ids) in the simulator, in ticks.
double simJoint1Ticks() {
  return serial_robot_driver::devices::body::sim::bodyStats(g_robot->stats()).servos.at(0).position;
}

/// The ticks of servo 2 in each sync-write (docs/protocols.md 2a: records (ID, POS_L, POS_H) from
/// byte 12) from frame `from` on.
std::vector<int> servo2Ticks(std::size_t from) {
  std::vector<int> ticks;
  const auto frames = g_tap->frames();
  for (std::size_t i = from; i < frames.size(); ++i) {
    const Bytes& f = frames[i].bytes;
    if (f.size() < 14 || f[0] != 0xFF || f[1] != 0xFF || f[2] != 0xFD || f[7] != 0x83) continue;
    for (std::size_t at = 12; at + 3 <= f.size() - 2; at += 3) {
      if (f[at] == 2) ticks.push_back(f[at + 1] | (f[at + 2] << 8));
    }
  }
  return ticks;
}

TEST(TrajectoryClock, ClockStepsChangeNothingOnTheWire) {
  ros::NodeHandle nh;
  test_support::TopicCounter<sensor_msgs::JointState> joint_states(nh, "joint_states", 5);
  ASSERT_TRUE(joint_states.waitForCount(5, kWait)) << "no joint_states from driver_node";
  Client client("follow_joint_trajectory", false);
  ASSERT_TRUE(waitFor([&] { return client.isServerConnected(); }, kWait));
  ASSERT_TRUE(waitFor([] { return std::abs(simJoint1Ticks() - 2048) < 1; }, kWait));

  // joint_1 from 0 to 1 rad (2048 -> 2700 ticks) in 4 s, well within the servos' speed.
  FollowJointTrajectoryGoal goal;
  goal.trajectory.joint_names = {"joint_1", "joint_2"};
  trajectory_msgs::JointTrajectoryPoint point;
  point.positions = {1.0, 0.0};
  point.time_from_start = ros::Duration(4.0);
  goal.trajectory.points.push_back(point);
  const std::size_t start = g_tap->frameCount();
  client.sendGoal(goal);

  ASSERT_TRUE(waitFor([] { return simJoint1Ticks() > 2048 + 130; }, kWait));  // ~20 %
  const std::size_t forward = g_tap->frameCount();
  g_clock->step(100.0);
  ASSERT_TRUE(waitFor([] { return simJoint1Ticks() > 2048 + 390; }, kWait));  // ~60 %
  const std::size_t backward = g_tap->frameCount();
  g_clock->step(-150.0);

  ASSERT_TRUE(waitFor([&] { return client.getState().isDone(); }, 60));
  EXPECT_EQ(client.getState(), State::SUCCEEDED) << client.getState().getText();

  // The result and the tap's copy of the wire come by different threads: wait for the last frame.
  const bool reached_end = waitFor(
      [&] {
        const std::vector<int> ticks = servo2Ticks(start);
        return !ticks.empty() && ticks.back() == 2700;
      },
      kWait);
  const std::vector<int> all = servo2Ticks(start);
  ASSERT_FALSE(all.empty());
  EXPECT_TRUE(reached_end) << "the last sync-write holds " << all.back() << " ticks, not 2700";
  for (std::size_t i = 1; i < all.size(); ++i) {
    ASSERT_GE(all[i], all[i - 1]) << "frame " << i << ": the trajectory was replayed";
  }
  // After each step the set-point still passes through many intermediate positions.
  for (const std::size_t mark : {forward, backward}) {
    const std::vector<int> after = servo2Ticks(mark);
    ASSERT_FALSE(after.empty());
    std::set<int> between;
    for (int t : after) {
      if (t > after.front() && t < 2700) between.insert(t);
    }
    EXPECT_GE(between.size(), 10u) << "the trajectory jumped to its end after a clock step";
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_trajectory_clock");
  ros::NodeHandle nh;
  ClockPublisher clock(nh);
  g_clock = &clock;

  const std::string port = test_support::nodeParam(kNode, "port");
  sim::SimOptions options;
  options.device("base").enabled = false;
  options.device("servo_bus").enabled = false;
  serial_robot_driver::devices::body::sim::bodyConfig(options).servo_ids = {2, 3};
  options.device("body").link = port + "_sim";
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  serial_robot_driver::protocol::FramerConfig framer;
  framer.accept(serial_robot_driver::devices::body::kSyncWriteFrames);
  test_support::PtyTap tap(port, *options.device("body").link, framer);
  g_tap = &tap;

  const int result = RUN_ALL_TESTS();
  robot.stop();
  return result;
}
