// The ROS-free joint groups and the clock trajectories run on: where a stop holds a streamed
// joint, the body's last commanded position, the bus joints' stop hook (a SPIN stop, never a
// move), one ROTATE per bus segment and the bus joints' freshness limit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/body/body_trajectory_joints.h"
#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"

namespace serial_robot_driver::trajectory {
namespace {

using devices::body::bodyTrajectoryJoints;
using devices::servo_bus::busStateTimeout;
using devices::servo_bus::busTrajectoryJoints;

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
  devices::body::JointCalibration reversed;
  reversed.zero_ticks = 1000;
  reversed.direction = -1;
  std::vector<devices::body::BodyJoint> joints = {{"joint_1", 1, {}}, {"joint_2", 2, reversed}};
  int frames = 0;
  devices::body::BodyController controller(joints, [&](const std::vector<uint8_t>&) {
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
  std::vector<devices::body::BodyJoint> joints = {{"joint_1", 1, {}}, {"joint_2", 2, {}}};
  devices::body::BodyController controller(joints,
                                           [](const std::vector<uint8_t>&) { return true; });
  const TrajectoryJoints group = bodyTrajectoryJoints(controller);
  ASSERT_TRUE(group.last_commanded);
  EXPECT_FALSE(group.stop);
  EXPECT_FALSE(group.last_commanded(0).has_value());
  ASSERT_TRUE(group.write({"joint_1"}, {-0.5}, std::nullopt).empty());
  // -0.5 rad = 2048 - 326 ticks (round(0.5 / kRadPerTick) = 326).
  ASSERT_TRUE(group.last_commanded(0).has_value());
  EXPECT_NEAR(*group.last_commanded(0), -326 * kRadPerTick, 1e-12);
  EXPECT_FALSE(group.last_commanded(1).has_value());
}

// A body frame carries the e-stop generation its trajectory was accepted under, to the gate.
TEST(TrajectoryStop, BodyJointsWriteThroughTheGateWithTheAcceptedGeneration) {
  std::vector<devices::body::BodyJoint> joints = {{"joint_1", 1, {}}, {"joint_2", 2, {}}};
  int frames = 0;
  devices::body::BodyController controller(joints, [&frames](const std::vector<uint8_t>&) {
    ++frames;
    return true;
  });
  const TrajectoryJoints group = bodyTrajectoryJoints(controller);
  ASSERT_TRUE(group.generation);
  const uint64_t accepted = group.generation();
  controller.gate().setLocked(true);
  controller.gate().setLocked(false);
  EXPECT_EQ(group.generation(), accepted + 1);
  EXPECT_EQ(group.write({"joint_1"}, {-0.5}, accepted),
            "joint command not written: e-stop engaged after this command was accepted");
  EXPECT_EQ(frames, 0);
  EXPECT_TRUE(group.write({"joint_1"}, {-0.5}, group.generation()).empty());
  EXPECT_EQ(frames, 1);
}

TEST(TrajectoryStop, BusJointStopIsAStopOfItsServoNeverAMove) {
  const std::vector<BusJoint> joints = {{9, "tilt", -20.0, -1}, {4, "pan", 0.0, 1}};
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

TEST(TrajectoryStop, SteadyNowNeverGoesBack) {
  const double first = steadyNow();
  const double second = steadyNow();
  EXPECT_GE(second, first);
}

TEST(TrajectoryJointGroups, BusSegmentIsOneRotateInTheServosDegrees) {
  const std::vector<BusJoint> joints = {{9, "tilt", -20.0, -1}};
  std::vector<std::tuple<uint8_t, double, uint32_t>> queued;
  const TrajectoryJoints group = busTrajectoryJoints(
      joints,
      [&](uint8_t id, double angle_deg, uint32_t interval_ms) {
        queued.emplace_back(id, angle_deg, interval_ms);
        return std::string();
      },
      20.0);
  ASSERT_EQ(group.joints.size(), 1u);
  EXPECT_EQ(group.joints[0].name, "tilt");
  EXPECT_FALSE(group.write);
  EXPECT_EQ(group.state_timeout, 0.5);  // three polls at 20 Hz are less
  EXPECT_TRUE(group.move(0, M_PI / 2, 0.7504).empty());
  ASSERT_EQ(queued.size(), 1u);
  EXPECT_EQ(std::get<0>(queued[0]), 9);
  EXPECT_NEAR(std::get<1>(queued[0]), -110.0, 1e-9);  // -20 - 90
  EXPECT_EQ(std::get<2>(queued[0]), 750u);
  EXPECT_EQ(busTrajectoryJoints(joints, {}, 2.0).state_timeout, 1.5);
}

}  // namespace
}  // namespace serial_robot_driver::trajectory
