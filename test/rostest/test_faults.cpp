// driver_node under abuse (faults.test launches the two nodes):
//
//  - UnplugReplug: the test plays the robot by hand on a pty at /unplug/driver_node's port and
//    closes and recreates it 100 times. After every replug the node must send a Reset before its
//    first speed frame and publish exactly the telemetry frames written to it; across the cycles
//    the node's open fds and threads must not grow (read from /proc/<pid>, the pid asked from the
//    node itself), and it must hold exactly one pty fd while connected and none once the port is
//    gone.
//  - Extreme*: /extreme/driver_node, with the simulator library in this process as the robot,
//    gets cmd_vel with huge, negative, NaN and Inf values, malformed joint_commands, and servo
//    requests with id 255, unknown names, huge and negative values and an empty parameter. The
//    node must stay alive and keep working; a rejected joint command or servo request must put no
//    byte on the wire, and every servo service must answer success = false with a reason.
//
// The machine may be busy (2 shared cores): the tests count frames and use generous deadlines.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/protocol/body_codec.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/fake_device.h"
#include "support/ros_test_support.h"

namespace {

namespace protocol = serial_robot_driver::protocol;
namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::TopicCounter;
using test_support::waitFor;

constexpr uint8_t kMsgWheelSpeed = 0x01;  // docs/protocols.md, section 1
constexpr uint8_t kMsgReset = 0x05;
constexpr double kTwoPi = 6.283185307179586;
// max_wheel_speed 1.0 m/s = 40.74 ticks per PID period (1600 ticks/rev, 0.25 m, 50 Hz); dithering
// sends 40 or 41.
constexpr int kMaxTicks = 41;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kHuge = std::numeric_limits<double>::max();

// =================================================================================================
// Unplug / replug
// =================================================================================================

/// Plays the robot on a pty at `path` (from plug() on): a FakeDevice that records the base frames
/// the node writes in the current session.
std::unique_ptr<test_support::FakeDevice> handPlayedRobot(const std::string& path) {
  protocol::FramerConfig config;
  config.base = true;
  return std::make_unique<test_support::FakeDevice>(path, config);
}

/// The MSGID of every base frame of the current session.
std::vector<uint8_t> msgIds(const test_support::FakeDevice& robot) {
  std::vector<uint8_t> ids;
  for (const auto& frame : robot.frames()) {
    if (frame.family != protocol::base::kFrames || frame.bytes.size() < 5) continue;
    ids.push_back(frame.bytes[4]);  // 55 AA LEN SEQ MSGID ...
  }
  return ids;
}

void writeTelemetry(test_support::FakeDevice& robot, int frames) {
  protocol::body::Telemetry telemetry;
  telemetry.servo_count = 2;
  telemetry.servos[0].position = 2048;
  telemetry.servos[1].position = 1024;
  telemetry.imu[protocol::body::kAccelZ] = 2048;
  const std::vector<uint8_t> bytes = protocol::body::encodeTelemetry(telemetry);
  for (int i = 0; i < frames; ++i) robot.write(bytes);
}

TEST(UnplugReplug, HundredCyclesRecoverEveryTimeWithoutLeaks) {
  const std::string node_name = "/unplug/driver_node";
  const std::string path = test_support::nodeParam(node_name, "port");
  ASSERT_FALSE(path.empty());
  ros::NodeHandle nh("unplug");
  TopicCounter<sensor_msgs::JointState> joints(nh, "joint_states", 10);
  ASSERT_TRUE(joints.waitConnected(20));
  int pid = -1;
  ASSERT_TRUE(waitFor([&] { return (pid = test_support::nodePid(node_name)) > 0; }, 20));

  constexpr int kCycles = 100;
  constexpr int kWarmUpCycles = 5;  // ROS connections and lazy allocations settle first
  constexpr int kTelemetryPerCycle = 3;
  const std::unique_ptr<test_support::FakeDevice> robot = handPlayedRobot(path);
  test_support::ProcessSample warm;
  test_support::ProcessSample last;
  std::vector<double> recovery_s;
  for (int cycle = 1; cycle <= kCycles; ++cycle) {
    const auto plugged_at = test_support::Clock::now();
    robot->plug();
    // Recovery: the node reopens the port and sends a Reset before its first speed frame.
    const bool driving = waitFor(
        [&] {
          for (uint8_t id : msgIds(*robot)) {
            if (id == kMsgWheelSpeed) return true;
          }
          return false;
        },
        20);
    ASSERT_TRUE(driving) << "cycle " << cycle << ": no speed frame after the replug";
    recovery_s.push_back(test_support::secondsSince(plugged_at));
    const std::vector<uint8_t> ids = msgIds(*robot);
    ASSERT_EQ(ids.front(), kMsgReset) << "cycle " << cycle << ": the first frame is not a Reset";

    // Telemetry flows: every frame written after the node reopened the port is published.
    const uint64_t before = joints.count();
    writeTelemetry(*robot, kTelemetryPerCycle);
    ASSERT_TRUE(joints.waitForCount(before + kTelemetryPerCycle, 20))
        << "cycle " << cycle << ": " << joints.count() - before << " of " << kTelemetryPerCycle
        << " telemetry frames published";

    if (cycle == kWarmUpCycles) warm = test_support::sampleProcess(pid);
    if (cycle == kCycles) last = test_support::sampleProcess(pid);
    if (cycle == kWarmUpCycles || cycle == kCycles) {
      EXPECT_EQ(test_support::ptyFdCount(pid), 1u) << "cycle " << cycle << ": one port, one fd";
    }
    robot->unplug();
  }
  // Nothing more than what was written (no duplicates).
  test_support::sleepSeconds(0.2);
  EXPECT_EQ(joints.count(), static_cast<uint64_t>(kCycles * kTelemetryPerCycle));

  // Once the port is gone the node holds no pty fd at all.
  EXPECT_TRUE(waitFor([&] { return test_support::ptyFdCount(pid) == 0; }, 10))
      << test_support::ptyFdCount(pid) << " pty fds left open after the unplug";
  EXPECT_TRUE(test_support::processAlive(pid));

  double worst = 0, sum = 0;
  for (double s : recovery_s) {
    worst = std::max(worst, s);
    sum += s;
  }
  std::printf("unplug/replug: %d cycles; fds %zu -> %zu, threads %zu -> %zu, RSS %ld -> %ld kB "
              "(after cycle %d -> after cycle %d); recovery mean %.0f ms, worst %.0f ms\n",
              kCycles, warm.fds, last.fds, warm.threads, last.threads, warm.rss_kb, last.rss_kb,
              kWarmUpCycles, kCycles, 1000 * sum / recovery_s.size(), 1000 * worst);
  // A tiny constant slack: a ROS connection (rosout, a master call) may be open at one sample
  // and not the other. A leak per cycle would show up as ~95 here.
  EXPECT_LE(last.fds, warm.fds + 2);
  EXPECT_LE(last.threads, warm.threads + 1);
}

// =================================================================================================
// Extreme inputs
// =================================================================================================

/// The simulated robot of /extreme/driver_node, started once for all Extreme* tests.
sim::RobotSim& extremeRobot() {
  static std::unique_ptr<sim::RobotSim> robot = [] {
    sim::SimOptions options;
    options.link = test_support::nodeParam("/extreme/driver_node", "port");
    auto created = std::make_unique<sim::RobotSim>(options);
    created->start();
    return created;
  }();
  return *robot;
}

int extremePid() {
  static const int pid = [] {
    int found = -1;
    waitFor([&] { return (found = test_support::nodePid("/extreme/driver_node")) > 0; }, 20);
    return found;
  }();
  return pid;
}

class ExtremeInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(test_support::nodeParam("/extreme/driver_node", "port").empty());
    extremeRobot();
    pid_ = extremePid();
    ASSERT_GT(pid_, 0);
  }
  void TearDown() override {
    EXPECT_TRUE(test_support::processAlive(pid_)) << "driver_node died";
    EXPECT_EQ(test_support::nodePid("/extreme/driver_node"), pid_) << "driver_node was restarted";
  }

  ros::NodeHandle nh_{"extreme"};
  int pid_ = -1;
};

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
      case Expect::kZero: return l == 0 && r == 0;
      case Expect::kForward: return l >= kMaxTicks - 1 && r >= kMaxTicks - 1;
      case Expect::kBackward: return l <= -(kMaxTicks - 1) && r <= -(kMaxTicks - 1);
      case Expect::kTurnLeft: return l <= -(kMaxTicks - 1) && r >= kMaxTicks - 1;
      case Expect::kTurnRight: return l >= kMaxTicks - 1 && r <= -(kMaxTicks - 1);
      case Expect::kBounded: return true;
      case Expect::kNormal: return std::abs(l - 20) <= 1 && std::abs(r - 20) <= 1;
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
  EXPECT_EQ(stats.base.unknown_frames, 0u);
  EXPECT_EQ(stats.framer.checksum_errors, 0u);
  EXPECT_EQ(stats.base.speed_frames_ignored, 0u);
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
  const uint64_t writes_before = robot.stats().body.sync_writes_ok;

  const auto command = [](std::vector<std::string> names, std::vector<double> positions) {
    sensor_msgs::JointState msg;
    msg.name = std::move(names);
    msg.position = std::move(positions);
    return msg;
  };
  const std::vector<sensor_msgs::JointState> malformed = {
      command({}, {}),                                  // empty
      command({"joint_1"}, {}),                         // a name without a position
      command({}, {0.5}),                               // a position without a name
      command({"joint_1", "joint_2"}, {0.5}),           // mismatched lengths
      command({"no_such_joint"}, {0.5}),                // unknown name
      command({""}, {0.5}),                             // empty name
      command({"joint_1"}, {kNaN}),                     // NaN
      command({"joint_1", "joint_2"}, {0.1, kInf}),     // Inf in the second
      command({"joint_1", "joint_1"}, {0.1, 0.2}),      // the same joint twice
  };
  for (const auto& msg : malformed) commands.publish(msg);
  // A good command last: once it is on the wire, every malformed one before it was handled.
  commands.publish(command({"joint_2"}, {0.5}));
  ASSERT_TRUE(waitFor([&] { return robot.stats().body.sync_writes_ok >= writes_before + 1; }, 20));
  test_support::sleepSeconds(0.3);
  sim::SimStats stats = robot.stats();
  EXPECT_EQ(stats.body.sync_writes_ok, writes_before + 1) << "a malformed command reached the wire";
  EXPECT_EQ(stats.body.sync_writes_malformed + stats.body_port_checksum_errors, 0u);
  ASSERT_EQ(stats.body.servos.size(), 2u);
  EXPECT_EQ(stats.body.servos[1].target, std::lround(2048 + 0.5 * 4096 / kTwoPi));

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
  const auto joint_1_target = robot.stats().body.servos[0].target;
  commands.publish(command({"joint_1"}, {1e9}));
  commands.publish(command({"joint_1"}, {-1e300}));
  commands.publish(command({"joint_1", "joint_2"}, {4.0, 0.25}));  // joint_2 alone goes out
  ASSERT_TRUE(waitFor([&] { return robot.stats().body.sync_writes_ok >= writes_before + 2; }, 20));
  test_support::sleepSeconds(0.3);
  EXPECT_EQ(robot.stats().body.sync_writes_ok, writes_before + 2);
  EXPECT_EQ(robot.stats().body.servos[0].target, joint_1_target);
  EXPECT_EQ(robot.stats().body.servos[1].target, std::lround(2048 + 0.25 * 4096 / kTwoPi));
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
struct Rejection {
  std::string request;
  bool call_ok = false;
  bool success = true;
  std::string message;
};

TEST_F(ExtremeInputs, ServoRequestsOutOfRangeFailCleanlyWithoutBytes) {
  sim::RobotSim& robot = extremeRobot();
  auto ping = nh_.serviceClient<srd::ServoPing>("servo/ping");
  auto read = nh_.serviceClient<srd::ServoRead>("servo/read");
  auto write = nh_.serviceClient<srd::ServoWrite>("servo/write");
  auto read_angle = nh_.serviceClient<srd::ServoReadAngle>("servo/read_angle");
  auto rotate = nh_.serviceClient<srd::ServoRotate>("servo/rotate");
  auto spin = nh_.serviceClient<srd::ServoSpin>("servo/spin");
  auto damping = nh_.serviceClient<srd::ServoDamping>("servo/damping");
  auto read_all = nh_.serviceClient<srd::ServoReadAll>("servo/read_all");
  auto reset = nh_.serviceClient<srd::ServoResetUserData>("servo/reset_user_data");
  ASSERT_TRUE(reset.waitForExistence(ros::Duration(20)));

  // The bus works, so a rejection below is the request's fault, not the wire's.
  srd::ServoPing alive;
  alive.request.id = 1;
  ASSERT_TRUE(waitFor([&] { return ping.call(alive) && alive.response.online; }, 20))
      << alive.response.message;

  const auto requests_on_wire = [&] {
    const sim::SimStats s = robot.stats();
    return s.framer.frames[static_cast<std::size_t>(protocol::servo::kRequestFrames)];
  };
  const uint64_t wire_before = requests_on_wire();
  const uint64_t sim_requests_before = robot.stats().servo_bus.requests;

  std::vector<Rejection> results;
  const auto record = [&](std::string what, bool call_ok, bool success, std::string message) {
    results.push_back({std::move(what), call_ok, success, std::move(message)});
  };
  {
    srd::ServoPing s;
    s.request.id = 255;
    const bool ok = ping.call(s);
    record("ping id 255", ok, s.response.online, s.response.message);
  }
  const auto doRead = [&](uint8_t id, const std::string& param) {
    srd::ServoRead s;
    s.request.id = id;
    s.request.param = param;
    const bool ok = read.call(s);
    record("read id " + std::to_string(id) + " '" + param + "'", ok, s.response.success,
           s.response.message);
  };
  doRead(255, "voltage");
  doRead(1, "");
  doRead(1, "no_such_param");
  doRead(1, "999");
  doRead(1, "-1");
  doRead(1, "51x");
  doRead(1, std::string(10000, 'x'));
  const auto doWrite = [&](uint8_t id, const std::string& param, int64_t value) {
    srd::ServoWrite s;
    s.request.id = id;
    s.request.param = param;
    s.request.value = value;
    const bool ok = write.call(s);
    record("write id " + std::to_string(id) + " '" + param.substr(0, 20) + "' = " +
               std::to_string(value),
           ok, s.response.success, s.response.message);
  };
  doWrite(1, "", 1);
  doWrite(1, "no_such_param", 1);
  doWrite(1, "angle_limit_low", std::numeric_limits<int64_t>::max());
  doWrite(1, "angle_limit_low", std::numeric_limits<int64_t>::min());
  doWrite(1, "angle_limit_high", 32768);
  doWrite(1, "soft_start_time", -1);    // unsigned 16-bit
  doWrite(1, "stall_power_limit", 65536);
  doWrite(1, "response_switch", 2);     // 0 or 1
  doWrite(1, "accel_switch", -128);     // unsigned 8-bit
  doWrite(1, "voltage", 5000);          // read-only
  doWrite(1, "servo_id", 3);            // dangerous, not armed
  doWrite(1, "baudrate", 3);            // dangerous, not armed
  doWrite(255, "soft_start_time", 10);  // broadcast: no read-back possible
  {
    srd::ServoReadAngle s;
    s.request.id = 255;
    const bool ok = read_angle.call(s);
    record("read_angle id 255", ok, s.response.success, s.response.message);
  }
  {
    srd::ServoReadAll s;
    s.request.id = 255;
    const bool ok = read_all.call(s);
    record("read_all id 255", ok, s.response.success, s.response.message);
  }
  const auto doRotate = [&](uint8_t id, double angle, bool wait, const std::string& what) {
    srd::ServoRotate s;
    s.request.id = id;
    s.request.angle_deg = angle;
    s.request.interval_ms = 100;
    s.request.wait = wait;
    const bool ok = rotate.call(s);
    record("rotate " + what, ok, s.response.success, s.response.message);
  };
  doRotate(1, kNaN, false, "NaN");
  doRotate(1, kInf, false, "+Inf");
  doRotate(1, -kInf, false, "-Inf");
  doRotate(1, 1e9, false, "1e9 deg");
  doRotate(1, -3276.9, false, "-3276.9 deg");
  doRotate(255, 10.0, true, "id 255 with wait");
  const auto doSpin = [&](uint8_t id, uint8_t mode, uint16_t speed, uint16_t value, bool wait,
                          const std::string& what) {
    srd::ServoSpin s;
    s.request.id = id;
    s.request.mode = mode;
    s.request.speed_dps = speed;
    s.request.value = value;
    s.request.wait = wait;
    const bool ok = spin.call(s);
    record("spin " + what, ok, s.response.success, s.response.message);
  };
  doSpin(1, 4, 100, 0, false, "mode 4");
  doSpin(1, 255, 100, 0, false, "mode 255");
  doSpin(255, 1, 100, 0, true, "id 255 with wait");
  doSpin(1, 2, 1, 65535, true, "65535 turns at 1 deg/s with wait");
  {
    srd::ServoDamping s;
    s.request.id = 255;
    s.request.power_mw = 65535;
    s.request.wait = true;
    const bool ok = damping.call(s);
    record("damping id 255 with wait", ok, s.response.success, s.response.message);
  }
  for (uint8_t id : {uint8_t{1}, uint8_t{255}}) {
    srd::ServoResetUserData s;
    s.request.id = id;
    const bool ok = reset.call(s);
    record("reset_user_data id " + std::to_string(id), ok, s.response.success,
           s.response.message);
  }

  for (const Rejection& r : results) {
    // (a 10000-character parameter name comes back in full: shortened here for the log)
    std::printf("%-45s -> %s\n", r.request.substr(0, 45).c_str(), r.message.substr(0, 160).c_str());
    EXPECT_TRUE(r.call_ok) << r.request << ": the call itself failed";
    EXPECT_FALSE(r.success) << r.request << " was accepted: " << r.message;
    EXPECT_GE(r.message.size(), 10u) << r.request << ": no reason given";
  }
  // Not one of them put a byte on the bus.
  EXPECT_EQ(requests_on_wire(), wire_before);
  EXPECT_EQ(robot.stats().servo_bus.requests, sim_requests_before);

  // And the bus still works.
  srd::ServoRead voltage;
  voltage.request.id = 1;
  voltage.request.param = "voltage";
  ASSERT_TRUE(read.call(voltage));
  EXPECT_TRUE(voltage.response.success) << voltage.response.message;
  EXPECT_EQ(voltage.response.unit, "mV");
  srd::ServoPing absent;
  absent.request.id = 200;  // not on the bus: a timeout, after a real request
  ASSERT_TRUE(ping.call(absent));
  EXPECT_FALSE(absent.response.online);
  EXPECT_FALSE(absent.response.message.empty());
  std::printf("%-45s -> %s\n", "ping id 200 (absent)", absent.response.message.c_str());
  EXPECT_TRUE(ping.call(alive) && alive.response.online) << alive.response.message;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_faults");
  return RUN_ALL_TESTS();
}
