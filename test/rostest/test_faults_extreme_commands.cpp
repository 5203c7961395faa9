// /extreme/driver_node (faults.test) gets cmd_vel with huge, negative, NaN and Inf values and
// malformed joint_commands: the wheels stay bounded or stop, a rejected joint command puts no byte
// on the wire, and the node keeps working.
#include <gtest/gtest.h>

#include "support/faults_support.h"

namespace {

using namespace faults_test;  // NOLINT: the shared fixture

TEST_F(ExtremeInputs, CmdVelIsBoundedOrStops) {
  TopicCounter<srd::WheelCommand> wheels(nh_, "wheel_command", 500);
  ros::Publisher cmd_vel = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  ASSERT_TRUE(wheels.waitConnected(20));
  ASSERT_TRUE(waitFor([&] { return cmd_vel.getNumSubscribers() > 0; }, 20));
  ASSERT_TRUE(wheels.waitForCount(5, 20)) << "no wheel frames";

  enum class Expect { kZero, kForward, kBackward, kTurnLeft, kTurnRight, kBounded, kNormal };
  struct Case {
    const char* name;
    double linear_x;
    double angular_z;
    Expect expect;
    double linear_y = 0.0;  // ignored by a differential drive, whatever it holds
  };
  const std::vector<Case> cases = {
      {"normal 0.5 m/s", 0.5, 0.0, Expect::kNormal},
      {"NaN linear", kNaN, 0.0, Expect::kZero},
      {"normal 0.5 m/s", 0.5, 0.0, Expect::kNormal},
      {"NaN angular", 0.0, kNaN, Expect::kZero},
      {"normal 0.5 m/s", 0.5, 0.0, Expect::kNormal},
      {"+Inf linear", kInf, 0.0, Expect::kZero},
      {"normal 0.5 m/s", 0.5, 0.0, Expect::kNormal},
      {"-Inf both", -kInf, -kInf, Expect::kZero},
      {"normal 0.5 m/s", 0.5, 0.0, Expect::kNormal},
      {"NaN and Inf", kNaN, kInf, Expect::kZero},
      {"1e300 forward", 1e300, 0.0, Expect::kForward},
      {"-1e300 backward", -1e300, 0.0, Expect::kBackward},
      {"1e300 turn left", 0.0, 1e300, Expect::kTurnLeft},
      {"-1e300 turn right", 0.0, -1e300, Expect::kTurnRight},
      {"-1e6 backward", -1e6, 0.0, Expect::kBackward},
      {"DBL_MAX both", kHuge, kHuge, Expect::kBounded},
      {"-DBL_MAX, DBL_MAX", -kHuge, kHuge, Expect::kBounded},
      {"denormal", 4.9e-324, -0.0, Expect::kZero},
      {"NaN in linear.y", 0.5, 0.0, Expect::kNormal, kNaN},
  };
  // 0.5 m/s: 20.4 ticks per period.
  const auto matches = [](Expect expect, const srd::WheelCommand& w) {
    const int l = w.left_ticks, r = w.right_ticks;
    switch (expect) {
      case Expect::kZero:
        return l == 0 && r == 0;
      case Expect::kForward:
        return l >= kMaxTicks - 1 && r >= kMaxTicks - 1;
      case Expect::kBackward:
        return l <= -(kMaxTicks - 1) && r <= -(kMaxTicks - 1);
      case Expect::kTurnLeft:
        return l <= -(kMaxTicks - 1) && r >= kMaxTicks - 1;
      case Expect::kTurnRight:
        return l >= kMaxTicks - 1 && r <= -(kMaxTicks - 1);
      case Expect::kBounded:
        return true;
      case Expect::kNormal:
        return std::abs(l - 20) <= 1 && std::abs(r - 20) <= 1;
    }
    return false;
  };
  for (const Case& c : cases) {
    geometry_msgs::Twist twist;
    twist.linear.x = c.linear_x;
    twist.linear.y = c.linear_y;
    twist.angular.z = c.angular_z;
    const uint64_t from = wheels.count();
    // Re-published until a frame shows it took effect (cmd_vel_timeout would zero it otherwise).
    const bool took_effect = waitFor(
        [&] {
          cmd_vel.publish(twist);
          const std::vector<srd::WheelCommand> seen = wheels.since(from);
          return seen.size() >= 3 && matches(c.expect, seen.back());
        },
        10);
    EXPECT_TRUE(took_effect) << c.name;
    // Whatever the command, no frame exceeds max_wheel_speed and the speeds are numbers.
    for (const srd::WheelCommand& w : wheels.since(from)) {
      EXPECT_LE(std::abs(w.left_ticks), kMaxTicks) << c.name;
      EXPECT_LE(std::abs(w.right_ticks), kMaxTicks) << c.name;
      EXPECT_TRUE(std::isfinite(w.left_speed) && std::isfinite(w.right_speed)) << c.name;
      EXPECT_LE(std::abs(w.left_speed), 1.0 + 1e-9) << c.name;
      EXPECT_LE(std::abs(w.right_speed), 1.0 + 1e-9) << c.name;
    }
    const std::vector<srd::WheelCommand> seen = wheels.since(from);
    if (!seen.empty()) {
      std::printf("cmd_vel %-20s -> ticks %4d %4d\n", c.name, int(seen.back().left_ticks),
                  int(seen.back().right_ticks));
    }
  }
  geometry_msgs::Twist stop;
  cmd_vel.publish(stop);
  // The base understood every frame it got.
  const sim::SimStats stats = extremeRobot().stats();
  EXPECT_EQ(srd::devices::base::sim::baseStats(stats).unknown_frames, 0u);
  EXPECT_EQ(stats.framer.checksum_errors, 0u);
  EXPECT_EQ(srd::devices::base::sim::baseStats(stats).speed_frames_ignored, 0u);
}

TEST_F(ExtremeInputs, MalformedJointCommandsAreRejectedWithoutBytes) {
  sim::RobotSim& robot = extremeRobot();
  ros::Publisher commands = nh_.advertise<sensor_msgs::JointState>("joint_commands", 50);
  TopicCounter<sensor_msgs::JointState> joints(nh_, "joint_states", 10);
  ros::NodeHandle root;
  test_support::DiagnosticsWatch diagnostics(root, "extreme/driver_node");
  ASSERT_TRUE(waitFor([&] { return commands.getNumSubscribers() > 0; }, 20));
  ASSERT_TRUE(joints.waitForCount(5, 20)) << "no telemetry";
  ASSERT_TRUE(waitFor([&] { return diagnostics.latest("body").received > 0; }, 20));
  const uint64_t rejected_before = diagnostics.latest("body").number("commands rejected");
  const uint64_t writes_before = srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok;

  const auto command = [](std::vector<std::string> names, std::vector<double> positions) {
    sensor_msgs::JointState msg;
    msg.name = std::move(names);
    msg.position = std::move(positions);
    return msg;
  };
  const std::vector<sensor_msgs::JointState> malformed = {
      command({}, {}),                               // empty
      command({"joint_1"}, {}),                      // a name without a position
      command({}, {0.5}),                            // a position without a name
      command({"joint_1", "joint_2"}, {0.5}),        // mismatched lengths
      command({"no_such_joint"}, {0.5}),             // unknown name
      command({""}, {0.5}),                          // empty name
      command({"joint_1"}, {kNaN}),                  // NaN
      command({"joint_1", "joint_2"}, {0.1, kInf}),  // Inf in the second
      command({"joint_1", "joint_1"}, {0.1, 0.2}),   // the same joint twice
  };
  for (const auto& msg : malformed) commands.publish(msg);
  // A good command last: once it is on the wire, every malformed one before it was handled.
  commands.publish(command({"joint_2"}, {0.5}));
  ASSERT_TRUE(waitFor(
      [&] {
        return srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok >=
               writes_before + 1;
      },
      20));
  test_support::sleepSeconds(0.3);
  sim::SimStats stats = robot.stats();
  EXPECT_EQ(srd::devices::body::sim::bodyStats(stats).sync_writes_ok, writes_before + 1)
      << "a malformed command reached the wire";
  EXPECT_EQ(srd::devices::body::sim::bodyStats(stats).sync_writes_malformed +
                srd::devices::body::sim::bodyStats(stats).port_checksum_errors,
            0u);
  ASSERT_EQ(srd::devices::body::sim::bodyStats(stats).servos.size(), 2u);
  EXPECT_EQ(srd::devices::body::sim::bodyStats(stats).servos[1].target,
            std::lround(2048 + 0.5 * 4096 / kTwoPi));

  // Every one of them counted as rejected (diagnostics are published once a second).
  const auto counted = diagnostics.waitFor(
      "body", 0,
      [&](const test_support::DiagnosticsWatch::Status& s) {
        return s.number("commands rejected") >= rejected_before + malformed.size();
      },
      [] { return true; }, 10);
  ASSERT_TRUE(counted.has_value());
  EXPECT_EQ(counted->number("commands rejected"), rejected_before + malformed.size());

  // Huge but finite positions are beyond what the servo can reach (0..4095 ticks): that joint is
  // left out, never clamped; a command with nothing reachable writes nothing.
  const auto joint_1_target = srd::devices::body::sim::bodyStats(robot.stats()).servos[0].target;
  commands.publish(command({"joint_1"}, {1e9}));
  commands.publish(command({"joint_1"}, {-1e300}));
  commands.publish(command({"joint_1", "joint_2"}, {4.0, 0.25}));  // joint_2 alone goes out
  ASSERT_TRUE(waitFor(
      [&] {
        return srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok >=
               writes_before + 2;
      },
      20));
  test_support::sleepSeconds(0.3);
  EXPECT_EQ(srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok, writes_before + 2);
  EXPECT_EQ(srd::devices::body::sim::bodyStats(robot.stats()).servos[0].target, joint_1_target);
  EXPECT_EQ(srd::devices::body::sim::bodyStats(robot.stats()).servos[1].target,
            std::lround(2048 + 0.25 * 4096 / kTwoPi));
  const auto out_of_range = diagnostics.waitFor(
      "body", 0,
      [](const test_support::DiagnosticsWatch::Status& s) {
        return s.number("joint targets out of range") >= 3;
      },
      [] { return true; }, 10);
  ASSERT_TRUE(out_of_range.has_value());
  EXPECT_EQ(out_of_range->number("joint targets out of range"), 3u);

  // Still publishing telemetry.
  const uint64_t joints_now = joints.count();
  EXPECT_TRUE(joints.waitForCount(joints_now + 10, 20));
}

/// One rejected servo request: the call returned, success is false and the message says why.

}  // namespace
