// What a stop writes (trajectory_stop.test): an empty trajectory, a cancel, and a retune of the bus
// poll, checked on the wire. The body is a test_support::FakeDevice (telemetry only when this test
// writes it; every sync-write recorded); the bus servos are sim::RobotSim behind a
// test_support::PtyTap that records every frame the node sends them. Expected bytes are written
// out by hand from docs/protocols.md. Outcomes are asserted, never durations.
#include <actionlib/client/simple_action_client.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
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

test_support::FakeDevice* g_body = nullptr;
test_support::PtyTap* g_bus = nullptr;
sim::RobotSim* g_robot = nullptr;

// docs/protocols.md 2a: a sync-write of two servos, up to the first record.
const Bytes kSyncWriteTwoHeader = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D,
                                   0x00, 0x83, 0x74, 0x00, 0x02, 0x00};

bool isSyncWrite(const Bytes& frame) {
  return frame.size() >= 12 && frame[0] == 0xFF && frame[1] == 0xFF && frame[2] == 0xFD &&
         frame[7] == 0x83;
}

/// The (id, ticks) records of a sync-write (ticks little-endian).
std::vector<std::pair<int, int>> records(const Bytes& frame) {
  std::vector<std::pair<int, int>> result;
  for (std::size_t at = 12; at + 3 <= frame.size() - 2; at += 3) {
    result.emplace_back(frame[at], frame[at + 1] | (frame[at + 2] << 8));
  }
  return result;
}

std::vector<Bytes> bodySyncWrites(std::size_t from = 0) {
  std::vector<Bytes> result;
  const auto frames = g_body->frames();
  for (std::size_t i = from; i < frames.size(); ++i) {
    if (isSyncWrite(frames[i].bytes)) result.push_back(frames[i].bytes);
  }
  return result;
}

/// Bus requests (12 4C CMD N id ...) to servo `id` the node wrote from frame `from` on.
std::vector<Bytes> busRequestsTo(uint8_t id, std::size_t from) {
  std::vector<Bytes> result;
  const auto frames = g_bus->frames();
  for (std::size_t i = from; i < frames.size(); ++i) {
    const Bytes& f = frames[i].bytes;
    if (f.size() >= 5 && f[0] == 0x12 && f[1] == 0x4C && f[4] == id) result.push_back(f);
  }
  return result;
}

bool isMotionToAnAngle(const Bytes& request) {
  const uint8_t cmd = request[2];
  return cmd == 0x08 || (cmd >= 0x0B && cmd <= 0x0F);  // ROTATE, CMD 11..15
}

/// The simulated bus servo 2's angle (deg).
double simServo2() {
  for (const auto& servo :
       serial_robot_driver::devices::servo_bus::sim::servoBusStats(g_robot->stats()).servos) {
    if (servo.id == 2) return servo.angle_deg;
  }
  return std::nan("");
}

FollowJointTrajectoryGoal goal(std::vector<std::string> names) {
  FollowJointTrajectoryGoal g;
  g.trajectory.joint_names = std::move(names);
  return g;
}

void addPoint(FollowJointTrajectoryGoal& g, std::vector<double> positions, double time) {
  trajectory_msgs::JointTrajectoryPoint p;
  p.positions = std::move(positions);
  p.time_from_start = ros::Duration(time);
  g.trajectory.points.push_back(p);
}

class TrajectoryStop : public ::testing::Test {
 protected:
  TrajectoryStop() : client_("follow_joint_trajectory", false), diagnostics_(nh_, "driver_node") {
    joint_commands_ = nh_.advertise<sensor_msgs::JointState>("joint_commands", 10);
  }
  void SetUp() override {
    ASSERT_TRUE(client_.waitForServer(ros::Duration(kWait)));
    // waitForServer() sees the node before the node counts this process's result subscription;
    // a result published in between would never arrive.
    ASSERT_TRUE(waitFor(
        [&] {
          return test_support::nodeCountsSubscriber(
              "/driver_node", nh_.resolveName("follow_joint_trajectory/result"));
        },
        kWait));
    ASSERT_TRUE(waitFor([&] { return joint_commands_.getNumSubscribers() > 0; }, kWait));
    // The body's port is open: a write now would reach the fake board.
    ASSERT_TRUE(diagnostics_.waitFor(
        "body", 0, [](const auto& status) { return status.flag("connected"); },
        [] { return ros::ok(); }, kWait));
  }
  void TearDown() override { stopTelemetry(); }

  /// Sends `g` and waits for its end; its final state.
  State run(const FollowJointTrajectoryGoal& g) {
    client_.sendGoal(g);
    EXPECT_TRUE(waitFor([&] { return client_.getState().isDone(); }, 60));
    return client_.getState();
  }
  std::string errorString() const {
    return client_.getResult() ? client_.getResult()->error_string : "";
  }

  /// The board's telemetry (section 2b golden frame: servo 2 at 2048, servo 3 at 1024), 50 Hz.
  void startTelemetry() {
    telemetry_on_ = true;
    telemetry_ = std::thread([this] {
      while (telemetry_on_) {
        g_body->write(golden::body::kTelemetryTwoServos);
        test_support::sleepSeconds(0.02);
      }
    });
  }
  void stopTelemetry() {
    telemetry_on_ = false;
    if (telemetry_.joinable()) telemetry_.join();
  }

  ros::NodeHandle nh_;
  Client client_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher joint_commands_;
  std::atomic<bool> telemetry_on_{false};
  std::thread telemetry_;
};

// First: nothing has been commanded or measured yet.
TEST_F(TrajectoryStop, EmptyTrajectoryWithoutTelemetryWritesNothing) {
  EXPECT_EQ(run(goal({"joint_1", "joint_2"})), State::SUCCEEDED);
  EXPECT_NE(errorString().find("'joint_1'"), std::string::npos) << errorString();
  EXPECT_NE(errorString().find("'joint_2'"), std::string::npos) << errorString();
  EXPECT_NE(errorString().find("left alone"), std::string::npos) << errorString();
  EXPECT_NE(client_.getState().getText().find("left alone"), std::string::npos)
      << client_.getState().getText();
  test_support::sleepSeconds(0.5);  // a few loop ticks
  EXPECT_TRUE(bodySyncWrites().empty()) << "a stop wrote a position it never commanded";

  // The port was open all along: a command does reach the board.
  sensor_msgs::JointState command;
  command.name = {"joint_1"};
  command.position = {0.0};
  joint_commands_.publish(command);
  ASSERT_TRUE(waitFor([] { return !bodySyncWrites().empty(); }, kWait));
  // id 2 -> 2048 only: LEN 0A (docs/protocols.md 2a).
  const Bytes first = bodySyncWrites().front();
  ASSERT_GE(first.size(), 15u);
  EXPECT_EQ(Bytes(first.begin(), first.begin() + 15),
            (Bytes{0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0A, 0x00, 0x83, 0x74, 0x00, 0x02, 0x00, 0x02,
                   0x00, 0x08}));
}

TEST_F(TrajectoryStop, EmptyTrajectoryHoldsTheCommandedTicks) {
  startTelemetry();  // measured: joint_1 at 2048, joint_2 at 1024
  // joint_1 0.5 rad = 2048 + 326 = 2374 (46 09); joint_2 -0.25 rad = 2048 - 163 = 1885 (5D 07).
  sensor_msgs::JointState command;
  command.name = {"joint_1", "joint_2"};
  command.position = {0.5, -0.25};
  joint_commands_.publish(command);
  const std::vector<std::pair<int, int>> commanded = {{2, 2374}, {3, 1885}};
  ASSERT_TRUE(waitFor(
      [&] {
        const auto writes = bodySyncWrites();
        return !writes.empty() && records(writes.back()) == commanded;
      },
      kWait));
  const std::size_t mark = g_body->frameCount();

  EXPECT_EQ(run(goal({"joint_1", "joint_2"})), State::SUCCEEDED) << client_.getState().getText();
  EXPECT_EQ(errorString(), "");
  ASSERT_TRUE(waitFor([&] { return !bodySyncWrites(mark).empty(); }, kWait))
      << "the stop wrote no hold frame";
  test_support::sleepSeconds(0.3);
  for (const Bytes& frame : bodySyncWrites(mark)) {
    ASSERT_GE(frame.size(), 18u);
    EXPECT_EQ(Bytes(frame.begin(), frame.begin() + 12), kSyncWriteTwoHeader);
    EXPECT_EQ(Bytes(frame.begin() + 12, frame.begin() + 18),
              (Bytes{0x02, 0x46, 0x09, 0x03, 0x5D, 0x07}))
        << "held elsewhere than commanded (2048 is 0 rad, 2048 / 1024 were measured)";
  }
}

TEST_F(TrajectoryStop, CancelStopsAFastBusJointWithoutAMoveBack) {
  // Start from servo 2 at rest near pan 0 (servo 0 deg).
  FollowJointTrajectoryGoal start = goal({"pan"});
  addPoint(start, {0.0}, 0.5);
  ASSERT_EQ(run(start), State::SUCCEEDED) << errorString();
  ASSERT_TRUE(waitFor([] { return std::abs(simServo2()) < 1.0; }, kWait));

  // 150 deg in 0.75 s: 200 deg/s, polled at 20 Hz.
  FollowJointTrajectoryGoal fast = goal({"pan"});
  addPoint(fast, {150.0 * M_PI / 180.0}, 0.75);
  client_.sendGoal(fast);
  ASSERT_TRUE(waitFor([] { return simServo2() > 30.0; }, kWait)) << "servo 2 did not turn";
  const std::size_t mark = g_bus->frameCount();
  const double at_cancel = simServo2();
  client_.cancelGoal();
  ASSERT_TRUE(waitFor([&] { return client_.getState().isDone(); }, kWait));
  EXPECT_EQ(client_.getState(), State::PREEMPTED);

  // A SPIN stop reaches servo 2: 12 4C 07 06 02 00 (mode 0 = stop), speed, value, SUM.
  ASSERT_TRUE(waitFor(
      [&] {
        for (const Bytes& f : busRequestsTo(2, mark)) {
          if (f.size() == 11 &&
              Bytes(f.begin(), f.begin() + 6) == Bytes{0x12, 0x4C, 0x07, 0x06, 0x02, 0x00}) {
            return true;
          }
        }
        return false;
      },
      kWait))
      << "no SPIN stop for servo 2 after the cancel";
  ASSERT_TRUE(waitFor(
      [] {
        for (const auto& servo :
             serial_robot_driver::devices::servo_bus::sim::servoBusStats(g_robot->stats()).servos) {
          if (servo.id == 2) return !servo.moving;
        }
        return false;
      },
      kWait));
  test_support::sleepSeconds(0.3);
  for (const Bytes& f : busRequestsTo(2, mark)) {
    EXPECT_FALSE(isMotionToAnAngle(f))
        << "a move to an angle after the cancel (CMD " << static_cast<int>(f[2]) << ")";
  }
  // Stopped where it was, not snapped back to an older angle.
  EXPECT_GE(simServo2(), at_cancel - 0.5);
}

TEST_F(TrajectoryStop, RetunedPollRateKeepsBusGoalsFresh) {
  dynamic_reconfigure::Reconfigure set;
  dynamic_reconfigure::DoubleParameter rate;
  rate.name = "state_rate";
  rate.value = 1.0;
  set.request.config.doubles.push_back(rate);
  const std::string service = std::string(kNode) + "/servo_bus/set_parameters";
  ASSERT_TRUE(ros::service::waitForService(service, 30000));
  ASSERT_TRUE(test_support::callService(service, set));
  test_support::sleepSeconds(1.5);  // the poll is at 1 Hz from its next round

  // At 1 Hz a measurement is up to 1 s old: the limit is now 3 s, not 0.5 s.
  FollowJointTrajectoryGoal g = goal({"pan"});
  addPoint(g, {0.3}, 1.5);
  addPoint(g, {0.3}, 4.0);
  g.goal_time_tolerance = ros::Duration(3.0);
  EXPECT_EQ(run(g), State::SUCCEEDED) << client_.getState().getText() << " " << errorString();

  rate.value = 20.0;
  set.request.config.doubles = {rate};
  EXPECT_TRUE(test_support::callService(service, set));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_trajectory_stop");
  serial_robot_driver::protocol::FramerConfig body_framer;
  body_framer.accept(serial_robot_driver::devices::body::kSyncWriteFrames);
  test_support::FakeDevice body(test_support::nodeParam(kNode, "port"), body_framer);
  body.plug();
  g_body = &body;

  const std::string bus_port = test_support::nodeParam(kNode, "servo_bus/port");
  sim::SimOptions options;
  options.device("base").enabled = false;
  options.device("body").enabled = false;
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).servo_ids = {2};
  options.device("servo_bus").link = bus_port + "_sim";
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  serial_robot_driver::protocol::FramerConfig bus_framer;
  bus_framer.accept(serial_robot_driver::devices::servo_bus::kRequestFrames);
  test_support::PtyTap tap(bus_port, *options.device("servo_bus").link, bus_framer);
  g_bus = &tap;

  const int result = RUN_ALL_TESTS();
  robot.stop();
  return result;
}
