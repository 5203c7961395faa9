// follow_joint_trajectory and joint_trajectory against the simulated body (sim::RobotSim in this
// process on the node's pty), whose servos follow each sync-write target at their speed bound
// (2048 ticks/s, pi rad/s). A C++ actionlib client, built against this package's copy of
// control_msgs' action, sends the goals. Outcomes are asserted, never durations: a goal's times
// only choose whether a servo can keep up.
#include <actionlib/client/simple_action_client.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"
#include "support/test_helpers.h"

namespace {

namespace sim = serial_robot_driver::sim;
using serial_robot_driver::FollowJointTrajectoryAction;
using serial_robot_driver::FollowJointTrajectoryGoal;
using serial_robot_driver::FollowJointTrajectoryResult;
using Client = actionlib::SimpleActionClient<FollowJointTrajectoryAction>;
using State = actionlib::SimpleClientGoalState;
using test_support::waitFor;

constexpr const char* kNode = "/driver_node";
constexpr double kRadPerTick = 2.0 * M_PI / 4096.0;  // the default calibration: zero at 2048

sim::RobotSim* g_robot = nullptr;

/// The simulated servo's position (rad) of joint_1 (index 0) or joint_2 (index 1).
double simJoint(std::size_t index) {
  return (serial_robot_driver::devices::body::sim::bodyStats(g_robot->stats())
              .servos.at(index)
              .position -
          2048.0) *
         kRadPerTick;
}
uint64_t syncWrites() {
  return serial_robot_driver::devices::body::sim::bodyStats(g_robot->stats()).sync_writes_ok;
}

/// The bus joint "pan": servo 2, zero at 30 deg, direction -1 (trajectory.test).
double simPan() {
  for (const auto& servo :
       serial_robot_driver::devices::servo_bus::sim::servoBusStats(g_robot->stats()).servos) {
    if (servo.id == 2) return -(servo.angle_deg - 30.0) * M_PI / 180.0;
  }
  return std::nan("");
}

trajectory_msgs::JointTrajectoryPoint point(std::vector<double> positions, double time) {
  trajectory_msgs::JointTrajectoryPoint p;
  p.positions = std::move(positions);
  p.time_from_start = ros::Duration(time);
  return p;
}

FollowJointTrajectoryGoal goalTo(std::vector<double> positions, double time,
                                 std::vector<std::string> names = {"joint_1", "joint_2"}) {
  FollowJointTrajectoryGoal goal;
  goal.trajectory.joint_names = std::move(names);
  goal.trajectory.points.push_back(point(std::move(positions), time));
  return goal;
}

class TrajectoryTest : public ::testing::Test {
 protected:
  TrajectoryTest()
      : client_("follow_joint_trajectory", false),
        other_client_("follow_joint_trajectory", false),
        joint_states_(nh_, "joint_states", 5) {
    topic_ = nh_.advertise<trajectory_msgs::JointTrajectory>("joint_trajectory", 10);
    joint_commands_ = nh_.advertise<sensor_msgs::JointState>("joint_commands", 10);
  }

  void SetUp() override {
    ASSERT_TRUE(joint_states_.waitForCount(5, 30)) << "no joint_states from driver_node";
    ASSERT_TRUE(client_.waitForServer(ros::Duration(30)));
    ASSERT_TRUE(other_client_.waitForServer(ros::Duration(30)));
    // waitForServer() sees the node before the node counts this process's result subscription;
    // a result published in between would never arrive.
    ASSERT_TRUE(waitFor(
        [&] {
          return test_support::nodeCountsSubscriber(
              "/driver_node", nh_.resolveName("follow_joint_trajectory/result"));
        },
        30));
    ASSERT_TRUE(waitFor([&] { return topic_.getNumSubscribers() > 0; }, 20));
    ASSERT_TRUE(waitFor([&] { return joint_commands_.getNumSubscribers() > 0; }, 20));
  }

  /// Sends and waits for the end; the result's error code.
  int run(const FollowJointTrajectoryGoal& goal, State::StateEnum expected) {
    client_.sendGoal(goal);
    EXPECT_TRUE(client_.waitForResult(ros::Duration(60)));
    EXPECT_EQ(client_.getState().state_, expected) << client_.getState().getText();
    return client_.getResult() ? client_.getResult()->error_code : std::numeric_limits<int>::min();
  }

  std::string errorString() const {
    return client_.getResult() ? client_.getResult()->error_string : "";
  }

  /// Waits until the simulated servos stand still (no sync-write moved them for a while).
  void waitStill() {
    double last0 = simJoint(0), last1 = simJoint(1);
    int still = 0;
    ASSERT_TRUE(waitFor(
        [&] {
          const double now0 = simJoint(0), now1 = simJoint(1);
          still = (now0 == last0 && now1 == last1) ? still + 1 : 0;
          last0 = now0;
          last1 = now1;
          return still >= 20;
        },
        30));
  }

  ros::NodeHandle nh_;
  Client client_;
  Client other_client_;
  test_support::TopicCounter<sensor_msgs::JointState> joint_states_;
  ros::Publisher topic_;
  ros::Publisher joint_commands_;
};

TEST_F(TrajectoryTest, GoalSucceedsAndTheServosGetThere) {
  // The callback owns its counter: a feedback the spinner thread delivers after the result (or
  // after a failed assertion left this function) must not write into a finished stack frame.
  auto feedbacks = std::make_shared<std::atomic<int>>(0);
  FollowJointTrajectoryGoal goal = goalTo({0.6, -0.4}, 1.0);
  goal.trajectory.points.insert(goal.trajectory.points.begin(), point({0.3, -0.2}, 0.5));
  client_.sendGoal(goal, Client::SimpleDoneCallback(), Client::SimpleActiveCallback(),
                   [feedbacks](const serial_robot_driver::FollowJointTrajectoryFeedbackConstPtr& f) {
                     if (f->joint_names.size() == 2 && f->desired.positions.size() == 2 &&
                         f->actual.positions.size() == 2) {
                       ++*feedbacks;
                     }
                   });
  ASSERT_TRUE(client_.waitForResult(ros::Duration(60)));
  EXPECT_EQ(client_.getState(), State::SUCCEEDED) << client_.getState().getText();
  EXPECT_EQ(client_.getResult()->error_code, FollowJointTrajectoryResult::SUCCESSFUL);
  EXPECT_GT(feedbacks->load(), 0);
  EXPECT_NEAR(simJoint(0), 0.6, 0.05);
  EXPECT_NEAR(simJoint(1), -0.4, 0.05);
}

TEST_F(TrajectoryTest, RejectedGoalsNameTheProblemAndWriteNothing) {
  waitStill();
  const uint64_t writes = syncWrites();

  EXPECT_EQ(run(goalTo({0.1, 0.1}, 1.0, {"joint_1", "elbow"}), State::REJECTED),
            FollowJointTrajectoryResult::INVALID_JOINTS);
  EXPECT_NE(errorString().find("'elbow'"), std::string::npos) << errorString();
  EXPECT_EQ(run(goalTo({0.1, 0.1}, 1.0, {"joint_1", "joint_1"}), State::REJECTED),
            FollowJointTrajectoryResult::INVALID_JOINTS);

  EXPECT_EQ(run(goalTo({0.1, std::nan("")}, 1.0), State::REJECTED),
            FollowJointTrajectoryResult::INVALID_GOAL);
  EXPECT_NE(errorString().find("joint 'joint_2', point 0"), std::string::npos) << errorString();

  FollowJointTrajectoryGoal backwards = goalTo({0.1, 0.1}, 1.0);
  backwards.trajectory.points.push_back(point({0.2, 0.2}, 0.5));
  EXPECT_EQ(run(backwards, State::REJECTED), FollowJointTrajectoryResult::INVALID_GOAL);
  EXPECT_NE(errorString().find("point 1"), std::string::npos) << errorString();

  EXPECT_EQ(run(goalTo({0.1}, 1.0), State::REJECTED), FollowJointTrajectoryResult::INVALID_GOAL);

  EXPECT_EQ(run(goalTo({0.1, 4.0}, 5.0), State::REJECTED),
            FollowJointTrajectoryResult::INVALID_GOAL);
  EXPECT_NE(errorString().find("joint 'joint_2', point 0"), std::string::npos) << errorString();

  // ~trajectory/max_velocity is 2 rad/s: 1 rad in 0.1 s is refused.
  EXPECT_EQ(run(goalTo({simJoint(0) + 1.0, simJoint(1)}, 0.1), State::REJECTED),
            FollowJointTrajectoryResult::INVALID_GOAL);
  EXPECT_NE(errorString().find("max_velocity"), std::string::npos) << errorString();

  FollowJointTrajectoryGoal old = goalTo({0.1, 0.1}, 1.0);
  old.trajectory.header.stamp = ros::Time::now() - ros::Duration(10.0);
  EXPECT_EQ(run(old, State::REJECTED), FollowJointTrajectoryResult::OLD_HEADER_TIMESTAMP);

  test_support::sleepSeconds(0.3);
  EXPECT_EQ(syncWrites(), writes) << "a rejected goal wrote to the body";
}

TEST_F(TrajectoryTest, PathToleranceViolated) {
  waitStill();
  // 1.5 rad in 0.8 s: the servo lags its set-point by far more than 1 mrad.
  FollowJointTrajectoryGoal goal = goalTo({simJoint(0) + 1.5, simJoint(1)}, 0.8);
  goal.path_tolerance.resize(1);
  goal.path_tolerance[0].name = "joint_1";
  goal.path_tolerance[0].position = 0.001;
  EXPECT_EQ(run(goal, State::ABORTED), FollowJointTrajectoryResult::PATH_TOLERANCE_VIOLATED);
  EXPECT_NE(errorString().find("joint 'joint_1'"), std::string::npos) << errorString();
}

TEST_F(TrajectoryTest, GoalToleranceViolated) {
  waitStill();
  // 0.5003 rad lies 0.00022 rad from the nearest tick: never within 0.0001 rad.
  FollowJointTrajectoryGoal goal = goalTo({0.5003, 0.0}, 1.0);
  goal.goal_tolerance.resize(1);
  goal.goal_tolerance[0].name = "joint_1";
  goal.goal_tolerance[0].position = 0.0001;
  goal.goal_time_tolerance = ros::Duration(0.2);
  EXPECT_EQ(run(goal, State::ABORTED), FollowJointTrajectoryResult::GOAL_TOLERANCE_VIOLATED);
  EXPECT_NE(errorString().find("joint 'joint_1'"), std::string::npos) << errorString();
}

TEST_F(TrajectoryTest, CancelHoldsTheJointsWhereTheyAre) {
  ASSERT_EQ(run(goalTo({-1.0, 0.0}, 1.5), State::SUCCEEDED), 0);
  waitStill();
  client_.sendGoal(goalTo({1.0, 0.0}, 4.0));
  ASSERT_TRUE(waitFor([] { return simJoint(0) > -0.7; }, 30));
  client_.cancelGoal();
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::PREEMPTED);
  waitStill();
  EXPECT_GT(simJoint(0), -0.8);
  EXPECT_LT(simJoint(0), 0.9) << "the cancelled goal went on";
}

TEST_F(TrajectoryTest, NewGoalForTheSameJointsPreempts) {
  waitStill();
  client_.sendGoal(goalTo({1.0, 0.5}, 4.0));
  ASSERT_TRUE(waitFor([&] { return client_.getState() == State::ACTIVE; }, 30));
  other_client_.sendGoal(goalTo({-0.2, 0.1}, 1.5));
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::PREEMPTED);
  ASSERT_TRUE(other_client_.waitForResult(ros::Duration(60)));
  EXPECT_EQ(other_client_.getState(), State::SUCCEEDED) << other_client_.getState().getText();
  EXPECT_NEAR(simJoint(0), -0.2, 0.05);
  EXPECT_NEAR(simJoint(1), 0.1, 0.05);
}

TEST_F(TrajectoryTest, TopicMovesTheJointsAndPreemptsAGoal) {
  waitStill();
  trajectory_msgs::JointTrajectory msg;
  msg.joint_names = {"joint_2", "joint_1"};
  msg.points = {point({0.3, 0.7}, 1.0)};
  topic_.publish(msg);
  ASSERT_TRUE(waitFor(
      [] { return std::abs(simJoint(0) - 0.7) < 0.01 && std::abs(simJoint(1) - 0.3) < 0.01; }, 30));

  client_.sendGoal(goalTo({-0.5, -0.5}, 4.0));
  ASSERT_TRUE(waitFor([&] { return client_.getState() == State::ACTIVE; }, 30));
  msg.points = {point({0.0, 0.0}, 1.0)};
  topic_.publish(msg);
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::PREEMPTED);
  ASSERT_TRUE(
      waitFor([] { return std::abs(simJoint(0)) < 0.01 && std::abs(simJoint(1)) < 0.01; }, 30));

  // A bad message is refused whole: nothing moves.
  waitStill();
  const uint64_t writes = syncWrites();
  msg.points = {point({0.5, 9.0}, 1.0)};
  topic_.publish(msg);
  test_support::sleepSeconds(0.5);
  EXPECT_EQ(syncWrites(), writes);
}

TEST_F(TrajectoryTest, JointCommandTakesOverAndAbortsTheGoal) {
  waitStill();
  client_.sendGoal(goalTo({1.0, 0.5}, 4.0));
  ASSERT_TRUE(waitFor([&] { return client_.getState() == State::ACTIVE; }, 30));
  sensor_msgs::JointState command;
  command.name = {"joint_2"};
  command.position = {-0.3};
  joint_commands_.publish(command);
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::ABORTED);
  EXPECT_NE(errorString().find("joint_commands"), std::string::npos) << errorString();
  ASSERT_TRUE(waitFor([] { return std::abs(simJoint(1) + 0.3) < 0.01; }, 30));
}

// The node's e-stop: the running goal aborts, and while it holds new goals are rejected and
// joint_trajectory and joint_commands move nothing; released, goals run again.
TEST_F(TrajectoryTest, EStopAbortsTheGoalAndRefusesMotionUntilReleased) {
  ros::Publisher e_stop = nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true);
  ASSERT_TRUE(waitFor([&] { return e_stop.getNumSubscribers() > 0; }, 20));
  waitStill();
  client_.sendGoal(goalTo({1.0, 0.5}, 4.0));
  ASSERT_TRUE(waitFor([&] { return client_.getState() == State::ACTIVE; }, 30));
  std_msgs::Bool engaged;
  engaged.data = true;
  e_stop.publish(engaged);
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::ABORTED);
  EXPECT_NE(errorString().find("e_stop"), std::string::npos) << errorString();
  waitStill();

  client_.sendGoal(goalTo({-0.5, -0.5}, 1.0));
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::REJECTED);
  const uint64_t writes = syncWrites();
  trajectory_msgs::JointTrajectory msg;
  msg.joint_names = {"joint_1"};
  msg.points = {point({0.2}, 1.0)};
  topic_.publish(msg);
  sensor_msgs::JointState command;
  command.name = {"joint_2"};
  command.position = {-0.3};
  joint_commands_.publish(command);
  test_support::sleepSeconds(1.0);
  EXPECT_EQ(syncWrites(), writes) << "a joint moved while the e-stop held";

  std_msgs::Bool released;
  released.data = false;
  e_stop.publish(released);
  test_support::sleepSeconds(0.5);
  EXPECT_EQ(run(goalTo({-0.2, 0.1}, 1.0), State::SUCCEEDED), 0) << errorString();
}

TEST_F(TrajectoryTest, BusServoJointFollowsOneMovePerSegment) {
  waitStill();
  sensor_msgs::JointState pan_state;
  test_support::TopicCounter<sensor_msgs::JointState> servo_states(nh_, "servo_states", 50);
  ASSERT_TRUE(servo_states.waitForCount(3, 30)) << "no servo_states";
  bool pan_named = false;
  for (const auto& msg : servo_states.since(0))
    pan_named |= !msg.name.empty() && msg.name[0] == "pan";
  EXPECT_TRUE(pan_named) << "servo_states does not name servo 2 'pan'";

  FollowJointTrajectoryGoal goal = goalTo({0.4}, 1.0, {"pan"});
  goal.trajectory.points.push_back(point({-0.5}, 2.5));
  EXPECT_EQ(run(goal, State::SUCCEEDED), FollowJointTrajectoryResult::SUCCESSFUL) << errorString();
  EXPECT_NEAR(simPan(), -0.5, 0.02);

  // One goal across a body joint and the bus joint.
  EXPECT_EQ(run(goalTo({0.2, 0.3}, 1.5, {"joint_1", "pan"}), State::SUCCEEDED),
            FollowJointTrajectoryResult::SUCCESSFUL)
      << errorString();
  EXPECT_NEAR(simJoint(0), 0.2, 0.05);
  EXPECT_NEAR(simPan(), 0.3, 0.02);

  // A motion service for the joint's servo takes it over: the goal aborts, saying by what.
  client_.sendGoal(goalTo({-1.0}, 4.0, {"pan"}));
  ASSERT_TRUE(waitFor([&] { return client_.getState() == State::ACTIVE; }, 30));
  serial_robot_driver::ServoRotate rotate;
  rotate.request.id = 2;
  rotate.request.angle_deg = 0.0;
  rotate.request.interval_ms = 200;
  ASSERT_TRUE(test_support::callService("servo/rotate", rotate));
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::ABORTED);
  EXPECT_NE(errorString().find("servo/rotate"), std::string::npos) << errorString();
  ASSERT_TRUE(waitFor([] { return std::abs(simPan() - 30.0 * M_PI / 180.0) < 0.02; }, 30))
      << "the trajectory went on after servo/rotate";

  // Beyond the servo's -180..180 deg: 30 deg - (-3.5 rad) is past 180 deg.
  EXPECT_EQ(run(goalTo({-3.5}, 5.0, {"pan"}), State::REJECTED),
            FollowJointTrajectoryResult::INVALID_GOAL);
  EXPECT_NE(errorString().find("joint 'pan', point 0"), std::string::npos) << errorString();
}

// Last: it stops the simulator.
TEST_F(TrajectoryTest, TelemetryLostAbortsTheGoal) {
  waitStill();
  client_.sendGoal(goalTo({simJoint(0) + 1.0, simJoint(1)}, 5.0));
  ASSERT_TRUE(waitFor([&] { return client_.getState() == State::ACTIVE; }, 30));
  g_robot->stop();
  ASSERT_TRUE(client_.waitForResult(ros::Duration(30)));
  EXPECT_EQ(client_.getState(), State::ABORTED);
  EXPECT_NE(errorString().find("telemetry lost"), std::string::npos) << errorString();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_trajectory");
  sim::SimOptions options;
  options.link = test_support::nodeParam(kNode, "port");
  options.device("base").enabled = false;
  options.device("servo_bus").enabled = true;
  return test_support::runAllTestsWithSim(options, &g_robot);
}
