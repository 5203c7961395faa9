// What a stop holds and the clock trajectories run on, without a roscore: the streamed joints'
// hold position, the body's last commanded position, the bus joints' stop hook (a SPIN stop, never
// a move), the steady start of a goal's ROS stamp and the bus joints' freshness limit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "serial_robot_driver/device/body_controller.h"
#include "serial_robot_driver/ros/trajectory_bus_joints.h"
#include "serial_robot_driver/ros/trajectory_joints.h"
#include "serial_robot_driver/ros/trajectory_server.h"

namespace serial_robot_driver::ros_layer {
namespace {

constexpr double kRadPerTick = 2.0 * M_PI / 4096.0;

TEST(TrajectoryStop, StreamedJointHoldsWhatTheServerLastWrote) {
  EXPECT_EQ(streamedHoldPosition(0.25, 0.5, 0.75), 0.25);
  EXPECT_EQ(streamedHoldPosition(0.25, std::nullopt, std::nullopt), 0.25);
}

TEST(TrajectoryStop, NeverWrittenHoldsTheDevicesLastCommand) {
  EXPECT_EQ(streamedHoldPosition(std::nullopt, 0.5, 0.75), 0.5);
  EXPECT_EQ(streamedHoldPosition(std::nullopt, 0.5, std::nullopt), 0.5);
}

TEST(TrajectoryStop, NeverCommandedHoldsAFreshMeasurementElseNothing) {
  EXPECT_EQ(streamedHoldPosition(std::nullopt, std::nullopt, 0.75), 0.75);
  // No default (0 rad), no old end point: nothing at all.
  EXPECT_FALSE(streamedHoldPosition(std::nullopt, std::nullopt, std::nullopt).has_value());
}

TEST(TrajectoryStop, BodyReportsItsLastCommandedPosition) {
  device::JointCalibration reversed;
  reversed.zero_ticks = 1000;
  reversed.direction = -1;
  std::vector<device::BodyJoint> joints = {{"joint_1", 1, {}}, {"joint_2", 2, reversed}};
  int frames = 0;
  device::BodyController controller(joints, [&](const std::vector<uint8_t>&) {
    ++frames;
    return true;
  });
  EXPECT_FALSE(controller.lastCommandedPosition(0).has_value());
  EXPECT_FALSE(controller.lastCommandedPosition(1).has_value());
  EXPECT_FALSE(controller.lastCommandedPosition(2).has_value());

  ASSERT_TRUE(controller.sendJointCommand({"joint_2"}, {0.1}).ok());
  EXPECT_FALSE(controller.lastCommandedPosition(0).has_value());
  // 0.1 rad on a reversed joint with zero at 1000: 1000 - round(0.1 / kRadPerTick) = 935 ticks.
  ASSERT_TRUE(controller.lastCommandedPosition(1).has_value());
  EXPECT_NEAR(*controller.lastCommandedPosition(1), -(935 - 1000) * kRadPerTick, 1e-12);

  // A rejected command changes nothing.
  EXPECT_FALSE(controller.sendJointCommand({"joint_2"}, {std::nan("")}).ok());
  EXPECT_NEAR(*controller.lastCommandedPosition(1), 65 * kRadPerTick, 1e-12);
  EXPECT_EQ(frames, 1);
}

TEST(TrajectoryStop, BodyJointsOfferTheLastCommandToTheServer) {
  std::vector<device::BodyJoint> joints = {{"joint_1", 1, {}}, {"joint_2", 2, {}}};
  device::BodyController controller(joints, [](const std::vector<uint8_t>&) { return true; });
  const TrajectoryJoints group = bodyTrajectoryJoints(controller);
  ASSERT_TRUE(group.last_commanded);
  EXPECT_FALSE(group.stop);
  EXPECT_FALSE(group.last_commanded(0).has_value());
  ASSERT_TRUE(group.write({"joint_1"}, {-0.5}).empty());
  // -0.5 rad = 2048 - 326 ticks (round(0.5 / kRadPerTick) = 326).
  ASSERT_TRUE(group.last_commanded(0).has_value());
  EXPECT_NEAR(*group.last_commanded(0), -326 * kRadPerTick, 1e-12);
  EXPECT_FALSE(group.last_commanded(1).has_value());
}

TEST(TrajectoryStop, BusJointStopIsAStopOfItsServoNeverAMove) {
  const std::vector<trajectory::BusJoint> joints = {{9, "tilt", -20.0, -1}, {4, "pan", 0.0, 1}};
  std::vector<uint8_t> stopped;
  int moves = 0;
  const TrajectoryJoints group = busTrajectoryJoints(
      joints,
      [&](uint8_t, double, uint32_t) {
        ++moves;
        return std::string();
      },
      10.0,
      [&](uint8_t id) {
        stopped.push_back(id);
        return std::string();
      });
  ASSERT_TRUE(group.stop);
  EXPECT_FALSE(group.last_commanded);
  EXPECT_TRUE(group.stop(1).empty());
  EXPECT_TRUE(group.stop(0).empty());
  EXPECT_EQ(stopped, (std::vector<uint8_t>{4, 9}));
  EXPECT_EQ(moves, 0);
  // Without a stop function there is no hook (a stop sends nothing).
  EXPECT_FALSE(busTrajectoryJoints(joints, {}, 10.0).stop);
}

TEST(TrajectoryStop, BusStateTimeoutFollowsThePollRate) {
  EXPECT_EQ(busStateTimeout(20.0), 0.5);  // three polls (0.15 s) are less than the floor
  EXPECT_EQ(busStateTimeout(6.0), 0.5);
  EXPECT_EQ(busStateTimeout(2.0), 1.5);
  EXPECT_EQ(busStateTimeout(1.0), 3.0);
  EXPECT_EQ(busStateTimeout(0.5), 6.0);
  EXPECT_EQ(busTrajectoryJoints({{9, "tilt", 0.0, 1}}, {}, 1.0).state_timeout, 3.0);
}

TEST(TrajectoryStop, GoalStampBecomesASteadyStartOnce) {
  // Zero: now on the steady clock, whatever the ROS clock says.
  EXPECT_EQ(steadyStart(ros::Time(), 500.0, ros::Time(1e9)), 500.0);
  // 2 s ahead of the ROS clock: 2 s ahead on the steady clock.
  EXPECT_NEAR(steadyStart(ros::Time(1000.0), 500.0, ros::Time(998.0)), 502.0, 1e-9);
  // 1.5 s behind.
  EXPECT_NEAR(steadyStart(ros::Time(1000.0), 500.0, ros::Time(1001.5)), 498.5, 1e-9);
}

TEST(TrajectoryStop, SteadyNowNeverGoesBack) {
  const double first = steadyNow();
  const double second = steadyNow();
  EXPECT_GE(second, first);
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
