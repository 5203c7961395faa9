// The ROS-side pieces of trajectories that need no roscore: messages to commands, bus joints from
// parameters, polled angles to joint measurements, and a goal's ROS stamp as a steady start.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/ros/trajectory_bus_joints.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/ros/trajectory_server.h"

namespace serial_robot_driver::ros_layer {
namespace {

using devices::servo_bus::ServoBusParams;

/// A goal's ROS stamp as the server starts it: converted, then the core's steadyStart().
double steadyStart(const ros::Time& stamp, double steady_now, const ros::Time& ros_now) {
  return trajectory::steadyStart(toMessageStamp(stamp), steady_now, toMessageStamp(ros_now));
}
double secondsBetween(const ros::Time& later, const ros::Time& earlier) {
  return trajectory::secondsBetween(toMessageStamp(later), toMessageStamp(earlier));
}

TEST(TrajectoryRos, CommandFromMessageKeepsEveryField) {
  trajectory_msgs::JointTrajectory msg;
  msg.joint_names = {"a", "b"};
  msg.points.resize(1);
  msg.points[0].positions = {0.1, 0.2};
  msg.points[0].velocities = {0.3, 0.4};
  msg.points[0].time_from_start = ros::Duration(1.25);
  const trajectory::TrajectoryCommand command = toTrajectoryCommand(msg);
  EXPECT_EQ(command.joint_names, msg.joint_names);
  ASSERT_EQ(command.points.size(), 1u);
  EXPECT_EQ(command.points[0].time_from_start, 1.25);
  EXPECT_EQ(command.points[0].velocities, (std::vector<double>{0.3, 0.4}));
  EXPECT_TRUE(command.points[0].accelerations.empty());
}

TEST(TrajectoryRos, BusJointsFromParametersWithDefaults) {
  ServoBusParams params;
  params.joint_ids = {5, 9};
  params.joint_names = {"pan", "tilt"};
  std::vector<trajectory::BusJoint> joints = devices::servo_bus::makeBusJoints(params);
  ASSERT_EQ(joints.size(), 2u);
  EXPECT_EQ(joints[1].id, 9);
  EXPECT_EQ(joints[1].name, "tilt");
  EXPECT_EQ(joints[1].zero_deg, 0.0);
  EXPECT_EQ(joints[1].direction, 1);
  params.joint_zero_deg = {10.0, -20.0};
  params.joint_directions = {1, -1};
  joints = devices::servo_bus::makeBusJoints(params);
  EXPECT_EQ(joints[1].zero_deg, -20.0);
  EXPECT_EQ(joints[1].direction, -1);
}

TEST(TrajectoryRos, PolledAngleBecomesTheJointsPosition) {
  const std::vector<trajectory::BusJoint> joints = {{9, "tilt", -20.0, -1}};
  // tilt = -(70 - (-20)) deg = -90 deg.
  sensor_msgs::JointState state =
      devices::servo_bus::ros::busJointState(joints, 9, 70.0, ros::Time(3.0));
  ASSERT_EQ(state.name.size(), 1u);
  EXPECT_EQ(state.name[0], "tilt");
  EXPECT_NEAR(state.position[0], -M_PI / 2, 1e-12);
  EXPECT_EQ(state.header.stamp, ros::Time(3.0));
  state = devices::servo_bus::ros::busJointState(joints, 4, 90.0, ros::Time(3.0));
  EXPECT_EQ(state.name[0], "servo_4");
  EXPECT_NEAR(state.position[0], M_PI / 2, 1e-12);
}

TEST(TrajectoryRos, GoalStampBecomesASteadyStartOnce) {
  // Zero: now on the steady clock, whatever the ROS clock says.
  EXPECT_EQ(steadyStart(ros::Time(), 500.0, ros::Time(1e9)), 500.0);
  // 2 s ahead of the ROS clock: 2 s ahead on the steady clock.
  EXPECT_NEAR(steadyStart(ros::Time(1000.0), 500.0, ros::Time(998.0)), 502.0, 1e-9);
  // 1.5 s behind.
  EXPECT_NEAR(steadyStart(ros::Time(1000.0), 500.0, ros::Time(1001.5)), 498.5, 1e-9);
}

TEST(TrajectoryRos, AnyStampGivesAFiniteStartWithoutThrowing) {
  // roscpp's Time - Time throws beyond 32-bit seconds ("Duration is out of dual 32-bit range"),
  // which ended the node from a joint_trajectory callback. Stamps as a message may carry them:
  // nsec not normalised, seconds at the ends of uint32.
  const ros::Time now(1.7e9);
  ros::Time far_future, epoch_start, unnormalised;
  far_future.sec = 4000000000u;
  epoch_start.nsec = 1;
  unnormalised.sec = 1700000000u;
  unnormalised.nsec = 4000000000u;  // 4 s more
  EXPECT_NEAR(steadyStart(far_future, 500.0, now), 500.0 + 2.3e9, 1.0);
  EXPECT_NEAR(steadyStart(epoch_start, 500.0, now), 500.0 - 1.7e9, 1.0);
  EXPECT_NEAR(steadyStart(unnormalised, 500.0, now), 504.0, 1e-6);
  ros::Time largest;
  largest.sec = largest.nsec = std::numeric_limits<uint32_t>::max();
  EXPECT_TRUE(std::isfinite(steadyStart(largest, 0.0, ros::Time(1.0))));
  EXPECT_NEAR(secondsBetween(ros::Time(1.0), largest), 1.0 - 4294967295.0 - 4.294967295, 1e-3);
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
