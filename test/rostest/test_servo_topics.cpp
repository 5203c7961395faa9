// servo_states and servo_commands end to end (servo_topics.test): driver_node polls servos 1, 2
// and 7 of a simulated bus (sim::RobotSim in this process, servos 0..3; 7 is absent) and moves
// them from servo_commands. Checked through the topics, the simulator's servo angles and the
// node's diagnostics. No timing assertions: every wait has a generous deadline.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
using test_support::TopicCounter;
using test_support::waitFor;

constexpr double kWaitSeconds = 20.0;
constexpr double kDegreesPerRadian = 180.0 / M_PI;
// The diagnostic status of the servo bus (after the node's prefix).
const char* const kServoBusStatus = "servo_bus";

sim::RobotSim* g_robot = nullptr;

std::optional<double> simAngleDeg(uint8_t id) {
  for (const serial_robot_driver::devices::servo_bus::sim::BusServoSnapshot& servo :
       serial_robot_driver::devices::servo_bus::sim::servoBusStats(g_robot->stats()).servos) {
    if (servo.id == id) return servo.angle_deg;
  }
  return std::nullopt;
}

/// The angle a target in rad becomes on the wire: int(deg * 10) / 10, as the vendor SDK sends it.
double wireDegrees(double radians) { return std::trunc(radians * kDegreesPerRadian * 10.0) / 10.0; }

sensor_msgs::JointState command(const std::vector<std::string>& names,
                                const std::vector<double>& positions,
                                const std::vector<double>& velocities = {}) {
  sensor_msgs::JointState msg;
  msg.name = names;
  msg.position = positions;
  msg.velocity = velocities;
  return msg;
}

class ServoTopics : public ::testing::Test {
 protected:
  ServoTopics() : states_(nh_, "servo_states", 200) {
    commands_ = nh_.advertise<sensor_msgs::JointState>("servo_commands", 10);
  }
  void SetUp() override {
    ASSERT_TRUE(states_.waitConnected(kWaitSeconds));
    ASSERT_TRUE(waitFor([&] { return commands_.getNumSubscribers() > 0; }, kWaitSeconds));
  }
  /// The latest servo_states position (rad) of `name` among the messages since `from`.
  std::optional<double> latestPosition(const std::string& name, uint64_t from = 0) const {
    std::optional<double> position;
    for (const sensor_msgs::JointState& msg : states_.since(from)) {
      for (std::size_t i = 0; i < msg.name.size(); ++i) {
        if (msg.name[i] == name && i < msg.position.size()) position = msg.position[i];
      }
    }
    return position;
  }
  bool waitForSimAngle(uint8_t id, double degrees) {
    return waitFor(
        [&] {
          const std::optional<double> angle = simAngleDeg(id);
          return angle && std::fabs(*angle - degrees) < 1e-6;
        },
        kWaitSeconds);
  }

  ros::NodeHandle nh_;
  TopicCounter<sensor_msgs::JointState> states_;
  ros::Publisher commands_;
};

TEST_F(ServoTopics, AnsweringServosArePublishedInRadiansWithTheirArrivalStamp) {
  ASSERT_TRUE(waitFor([&] { return latestPosition("servo_1") && latestPosition("servo_2"); },
                      kWaitSeconds));
  for (const sensor_msgs::JointState& msg : states_.since(0)) {
    ASSERT_EQ(msg.name.size(), 1u);
    EXPECT_TRUE(msg.name[0] == "servo_1" || msg.name[0] == "servo_2") << msg.name[0];
    EXPECT_FALSE(msg.header.stamp.isZero());
    EXPECT_LE(msg.header.stamp, ros::Time::now());
  }
}

TEST_F(ServoTopics, ACommandWithoutVelocityRotatesTheServo) {
  commands_.publish(command({"servo_1"}, {0.5}));
  ASSERT_TRUE(waitForSimAngle(1, wireDegrees(0.5)));
  // The poll reports the new angle (READ_ANGLE resolution 0.1 deg).
  const uint64_t from = states_.count();
  ASSERT_TRUE(waitFor(
      [&] {
        const std::optional<double> position = latestPosition("servo_1", from);
        return position && std::fabs(*position - wireDegrees(0.5) / kDegreesPerRadian) < 1e-9;
      },
      kWaitSeconds));
}

TEST_F(ServoTopics, ACommandWithAVelocityMovesByVelocity) {
  commands_.publish(command({"servo_2"}, {-1.0}, {2.0}));
  ASSERT_TRUE(waitForSimAngle(2, wireDegrees(-1.0)));
}

TEST_F(ServoTopics, ABadMessageIsRejectedWholeAndNothingIsSent) {
  commands_.publish(command({"servo_3"}, {0.0}));
  ASSERT_TRUE(waitForSimAngle(3, 0.0));
  // Each of these names servo 3 next to a fault: none of servo 3's targets may reach the bus.
  commands_.publish(command({"servo_3", "servo_x"}, {0.3, 0.1}));
  commands_.publish(command({"servo_3", "servo_255"}, {0.3, 0.1}));
  commands_.publish(command({"servo_3", "servo_1"}, {0.3, std::nan("")}));
  commands_.publish(command({"servo_3"}, {0.3, 0.4}));
  // A good command published after them lands on the bus after them (one queue, in order).
  commands_.publish(command({"servo_0"}, {0.2}));
  ASSERT_TRUE(waitForSimAngle(0, wireDegrees(0.2)));
  EXPECT_DOUBLE_EQ(*simAngleDeg(3), 0.0);

  ros::NodeHandle nh;
  const test_support::DiagnosticsWatch diagnostics(nh, "driver_node");
  EXPECT_TRUE(waitFor(
      [&] { return diagnostics.latest(kServoBusStatus).number("servo_commands rejected") >= 4; },
      kWaitSeconds));
}

TEST_F(ServoTopics, DiagnosticsCompareTheAskedAndTheAchievedReadRate) {
  ros::NodeHandle nh;
  const test_support::DiagnosticsWatch diagnostics(nh, "driver_node");
  // Servos 1 and 2 answer at 20 Hz each; servo 7 is silent, in back-off, and not asked for.
  EXPECT_TRUE(waitFor(
      [&] {
        const auto status = diagnostics.latest(kServoBusStatus);
        return status.number("servo_states asked (per s)") == 40.0 &&
               status.number("servo_states achieved (per s)") > 0.0;
      },
      kWaitSeconds))
      << "no servo_states asked/achieved rates in the diagnostics";
}

TEST_F(ServoTopics, AServoThatDoesNotAnswerIsSkippedAndReported) {
  ros::NodeHandle nh;
  const test_support::DiagnosticsWatch diagnostics(nh, "driver_node");
  EXPECT_TRUE(waitFor(
      [&] { return diagnostics.latest(kServoBusStatus).value("polled servos offline") == "7"; },
      kWaitSeconds));
  EXPECT_FALSE(latestPosition("servo_7").has_value());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_topics");
  const std::string port = test_support::nodeParam("/driver_node", "port");
  if (port.empty()) {
    std::fprintf(stderr, "the .test file must set /driver_node/port\n");
    return 1;
  }
  sim::SimOptions options;
  options.device("base").enabled = false;
  options.device("body").enabled = false;
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).servo_ids = {0, 1, 2, 3};
  options.device("servo_bus").link = port;
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  const int result = RUN_ALL_TESTS();
  g_robot = nullptr;
  return result;
}
