// Safe motion end to end (safe_motion.test): the e-stop stops a spinning bus servo and refuses
// motion until released while reads still work; servo/relax and servo/hold; a servo set spinning
// is stopped when the node gets SIGINT and relaxed (~servo_bus/on_shutdown: relax) when its
// nodelet is unloaded; a hot servo reported in /diagnostics and, with ~servo_bus/protect, relaxed
// and refused. Checked through the simulator's servos (sim::RobotSim in this process),
// the services' answers and /diagnostics. No timing assertions: every wait has a generous deadline.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoHold.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/process_support.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::waitFor;

constexpr double kWaitSeconds = 20.0;

sim::RobotSim* g_robot = nullptr;
std::string g_port;

std::unique_ptr<sim::RobotSim> makeBus(
    const std::string& port,
    const serial_robot_driver::devices::servo_bus::sim::ServoBusSimConfig& bus = {}) {
  sim::SimOptions options;
  options.device("base").enabled = false;
  options.device("body").enabled = false;
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options) = bus;
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).servo_ids = {0, 1, 2, 3};
  options.device("servo_bus").link = port;
  auto robot = std::make_unique<sim::RobotSim>(options);
  robot->start();
  return robot;
}

std::optional<serial_robot_driver::devices::servo_bus::sim::BusServoSnapshot> simServo(
    const sim::RobotSim& robot, uint8_t id) {
  for (const serial_robot_driver::devices::servo_bus::sim::BusServoSnapshot& servo :
       serial_robot_driver::devices::servo_bus::sim::servoBusStats(robot.stats()).servos) {
    if (servo.id == id) return servo;
  }
  return std::nullopt;
}

bool waitMoving(const sim::RobotSim& robot, uint8_t id, bool moving) {
  return waitFor(
      [&] {
        const auto servo = simServo(robot, id);
        return servo && servo->moving == moving;
      },
      kWaitSeconds);
}

/// servo/spin `id` continuously in namespace `ns`; the service's answer.
srd::ServoSpin spin(const std::string& ns, uint8_t id, uint8_t mode = 1) {
  srd::ServoSpin call;
  call.request.id = id;
  call.request.mode = mode;
  call.request.speed_dps = 90;
  EXPECT_TRUE(ros::service::waitForService(ns + "/servo/spin", 30000));
  EXPECT_TRUE(test_support::callService(ns + "/servo/spin", call));
  return call;
}

/// spin() once the node's port is open (its services come up before the port does).
bool spinOnceConnected(const std::string& ns, uint8_t id) {
  return waitFor([&] { return spin(ns, id).response.success; }, kWaitSeconds);
}

class SafeMotion : public ::testing::Test {
 protected:
  SafeMotion() : diagnostics_(nh_, "driver_node") {
    e_stop_ = nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true);
    commands_ = nh_.advertise<sensor_msgs::JointState>("servo_commands", 10);
  }
  void SetUp() override {
    ASSERT_TRUE(waitFor([&] { return e_stop_.getNumSubscribers() > 0; }, kWaitSeconds));
    ASSERT_TRUE(waitFor([&] { return commands_.getNumSubscribers() > 0; }, kWaitSeconds));
    setEStop(false);
  }
  void TearDown() override {
    setEStop(false);
    spin("", 1, 0);
    spin("", 2, 0);
  }
  void setEStop(bool engaged) {
    ASSERT_TRUE(test_support::setEStopAndWait(e_stop_, diagnostics_, engaged, kWaitSeconds));
  }

  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher e_stop_;
  ros::Publisher commands_;
};

TEST_F(SafeMotion, EStopStopsASpinningServoAndRefusesMotionUntilReleased) {
  ASSERT_TRUE(spin("", 1).response.success);
  ASSERT_TRUE(waitMoving(*g_robot, 1, true));

  setEStop(true);
  ASSERT_TRUE(waitMoving(*g_robot, 1, false)) << "servo 1 still spins after e_stop";
  const double stopped_at = simServo(*g_robot, 1)->angle_deg;

  // Motion is refused, with a message, by every way in.
  const srd::ServoSpin refused_spin = spin("", 1);
  EXPECT_FALSE(refused_spin.response.success);
  EXPECT_NE(refused_spin.response.message.find("e_stop"), std::string::npos)
      << refused_spin.response.message;
  srd::ServoRotate rotate;
  rotate.request.id = 1;
  rotate.request.angle_deg = 90.0;
  ASSERT_TRUE(test_support::callService("servo/rotate", rotate));
  EXPECT_FALSE(rotate.response.success);
  srd::ServoHold hold;
  ASSERT_TRUE(test_support::callService("servo/hold", hold));
  EXPECT_FALSE(hold.response.success);
  sensor_msgs::JointState command;
  command.name = {"servo_1"};
  command.position = {1.0};
  commands_.publish(command);

  // Reads and pings still work.
  srd::ServoReadAngle read;
  read.request.id = 1;
  ASSERT_TRUE(test_support::callService("servo/read_angle", read));
  EXPECT_TRUE(read.response.success) << read.response.message;
  srd::ServoPing ping;
  ping.request.id = 2;
  ASSERT_TRUE(test_support::callService("servo/ping", ping));
  EXPECT_TRUE(ping.response.online) << ping.response.message;

  // The refusals are counted, servo_commands among them, and nothing moved.
  const uint64_t seen = diagnostics_.latest("e_stop").received;
  const auto status = diagnostics_.waitFor(
      "e_stop", seen, [](const auto& s) { return s.number("refused: servo_commands") >= 1; },
      [] { return ros::ok(); }, kWaitSeconds);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_GE(status->number("refused: servo/spin"), 1u);
  EXPECT_GE(status->number("refused: servo/rotate"), 1u);
  EXPECT_GE(status->number("refused: servo/hold"), 1u);
  EXPECT_FALSE(simServo(*g_robot, 1)->moving);
  EXPECT_EQ(simServo(*g_robot, 1)->angle_deg, stopped_at);

  // Released: motion is obeyed again.
  setEStop(false);
  ASSERT_TRUE(test_support::callService("servo/rotate", rotate));
  EXPECT_TRUE(rotate.response.success) << rotate.response.message;
  EXPECT_TRUE(waitFor([&] { return std::fabs(simServo(*g_robot, 1)->angle_deg - 90.0) < 1e-6; },
                      kWaitSeconds));
}

TEST_F(SafeMotion, RelaxDampsEveryConfiguredServoAndHoldKeepsTheAngle) {
  srd::ServoRelax relax;  // no ids: every configured servo (1 and 2)
  ASSERT_TRUE(test_support::callService("servo/relax", relax));
  EXPECT_TRUE(relax.response.success) << relax.response.message;
  EXPECT_TRUE(
      waitFor([&] { return simServo(*g_robot, 1)->relaxed && simServo(*g_robot, 2)->relaxed; },
              kWaitSeconds));
  EXPECT_FALSE(simServo(*g_robot, 3)->relaxed) << "servo 3 is not configured";

  // A servo spinning is held where it is: it stops, and holds (no longer relaxed).
  ASSERT_TRUE(spin("", 2).response.success);
  ASSERT_TRUE(waitMoving(*g_robot, 2, true));
  srd::ServoHold hold;
  hold.request.ids = {2};
  ASSERT_TRUE(test_support::callService("servo/hold", hold));
  EXPECT_TRUE(hold.response.success) << hold.response.message;
  ASSERT_TRUE(waitMoving(*g_robot, 2, false));
  EXPECT_FALSE(simServo(*g_robot, 2)->relaxed);
  EXPECT_TRUE(simServo(*g_robot, 1)->relaxed) << "servo 1 was not named";
}

// The node stopped with SIGINT while a servo spins: the servo is stopped before the port closes.
TEST(SafeMotionProcess, SigintStopsASpinningServo) {
  const std::string port = g_port + "_sigint";
  auto robot = makeBus(port);
  test_support::ChildProcess node(
      test_support::findDriverNode(),
      {"__ns:=/sig", "__name:=driver_sig", "_port:=" + port, "_reconnect_interval:=0.2",
       "_base/enabled:=false", "_body/enabled:=false"});
  ASSERT_TRUE(node.started());
  ASSERT_TRUE(spinOnceConnected("/sig", 3)) << node.output();
  ASSERT_TRUE(waitMoving(*robot, 3, true)) << node.output();

  node.signal(SIGINT);
  const auto status = node.waitExit(20.0);
  ASSERT_TRUE(status.has_value()) << "driver_node did not exit on SIGINT";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << node.output();
  EXPECT_TRUE(waitMoving(*robot, 3, false)) << node.output();
  EXPECT_FALSE(simServo(*robot, 3)->relaxed);
}

// The nodelet unloaded while a servo spins, ~servo_bus/on_shutdown relax: the servo is relaxed.
TEST(SafeMotionProcess, NodeletUnloadRelaxesASpinningServo) {
  const std::string port = g_port + "_unload";
  auto robot = makeBus(port);
  ros::param::set("/unl/driver_node/port", port);
  ros::param::set("/unl/driver_node/reconnect_interval", 0.2);
  ros::param::set("/unl/driver_node/base/enabled", false);
  ros::param::set("/unl/driver_node/body/enabled", false);
  ros::param::set("/unl/driver_node/servo_bus/on_shutdown", std::string("relax"));
  test_support::ChildProcess manager("rosrun",
                                     {"nodelet", "nodelet", "manager", "__name:=unl_manager"});
  ASSERT_TRUE(manager.started());
  ASSERT_TRUE(ros::service::waitForService("/unl_manager/load_nodelet", 30000)) << manager.output();
  nodelet::NodeletLoad load;
  load.request.name = "/unl/driver_node";
  load.request.type = "serial_robot_driver/DriverNodelet";
  ASSERT_TRUE(test_support::callService("/unl_manager/load_nodelet", load)) << manager.output();
  ASSERT_TRUE(load.response.success) << manager.output();

  ASSERT_TRUE(spinOnceConnected("/unl", 0)) << manager.output();
  ASSERT_TRUE(waitMoving(*robot, 0, true)) << manager.output();

  nodelet::NodeletUnload unload;
  unload.request.name = "/unl/driver_node";
  ASSERT_TRUE(test_support::callService("/unl_manager/unload_nodelet", unload));
  EXPECT_TRUE(unload.response.success);
  EXPECT_TRUE(waitMoving(*robot, 0, false)) << manager.output();
  EXPECT_TRUE(simServo(*robot, 0)->relaxed) << manager.output();

  manager.signal(SIGINT);
  manager.waitExit(20.0);
}

// Health: servo 1 hot (70 degC, its limit 65), servo 2's voltage near its lower limit (4900 mV,
// limit 4500), servo 7 absent; with ~servo_bus/protect the hot servo is relaxed and its moves
// refused, while servo 2 still moves.
TEST(SafeMotionProcess, AHotServoIsReportedRelaxedAndRefused) {
  const std::string port = g_port + "_hot";
  serial_robot_driver::devices::servo_bus::sim::ServoBusSimConfig bus;
  bus.temperature_c[1] = 70;
  bus.voltage_mv[2] = 4900;
  auto robot = makeBus(port, bus);
  ros::param::set("/hot/driver_hot/servo_bus/state_ids", std::vector<int>{1, 2, 7});
  ros::param::set("/hot/driver_hot/servo_bus/health_rate", 5.0);
  ros::param::set("/hot/driver_hot/servo_bus/protect", true);
  ros::param::set("/hot/driver_hot/servo_bus/timeout", 0.1);
  ros::param::set("/hot/driver_hot/diagnostic_period", 0.2);
  ros::NodeHandle nh;
  test_support::DiagnosticsWatch diagnostics(nh, "hot/driver_hot");
  test_support::ChildProcess node(
      test_support::findDriverNode(),
      {"__ns:=/hot", "__name:=driver_hot", "_port:=" + port, "_reconnect_interval:=0.2",
       "_base/enabled:=false", "_body/enabled:=false"});
  ASSERT_TRUE(node.started());
  using Status = test_support::DiagnosticsWatch::Status;
  const auto keep_waiting = [] { return ros::ok(); };
  // The status of the reading past the limit (before the port connects, the servo's status is
  // an ERROR of another kind: it does not answer).
  const auto hot = diagnostics.waitFor(
      "servo_bus servo 1", 0,
      [](const Status& s) {
        return s.level == diagnostic_msgs::DiagnosticStatus::ERROR &&
               s.message.find("over_temperature") != std::string::npos;
      },
      keep_waiting, kWaitSeconds);
  ASSERT_TRUE(hot.has_value()) << node.output();
  EXPECT_NE(hot->message.find("servo 1"), std::string::npos) << hot->message;
  EXPECT_NE(hot->message.find("over_temperature 65 degC"), std::string::npos) << hot->message;
  EXPECT_EQ(hot->value("temperature (degC)"), "70");
  const auto low = diagnostics.waitFor(
      "servo_bus servo 2", 0,
      [](const Status& s) { return s.level == diagnostic_msgs::DiagnosticStatus::WARN; },
      keep_waiting, kWaitSeconds);
  ASSERT_TRUE(low.has_value()) << node.output();
  EXPECT_NE(low->message.find("over_volt_low 4500 mV"), std::string::npos) << low->message;
  const auto offline = diagnostics.waitFor(
      "servo_bus servo 7", 0,
      [](const Status& s) { return s.level == diagnostic_msgs::DiagnosticStatus::ERROR; },
      keep_waiting, kWaitSeconds);
  ASSERT_TRUE(offline.has_value()) << node.output();
  EXPECT_NE(offline->message.find("does not answer"), std::string::npos) << offline->message;

  // protect: relaxed, and its moves refused; the other servo still moves.
  EXPECT_TRUE(waitFor([&] { return simServo(*robot, 1)->relaxed; }, kWaitSeconds));
  srd::ServoRotate rotate;
  rotate.request.id = 1;
  rotate.request.angle_deg = 45.0;
  ASSERT_TRUE(test_support::callService("/hot/servo/rotate", rotate));
  EXPECT_FALSE(rotate.response.success);
  EXPECT_NE(rotate.response.message.find("over_temperature"), std::string::npos)
      << rotate.response.message;
  rotate.request.id = 2;
  ASSERT_TRUE(test_support::callService("/hot/servo/rotate", rotate));
  EXPECT_TRUE(rotate.response.success) << rotate.response.message;
  EXPECT_TRUE(waitFor([&] { return std::fabs(simServo(*robot, 2)->angle_deg - 45.0) < 1e-6; },
                      kWaitSeconds));
  EXPECT_TRUE(simServo(*robot, 1)->relaxed);

  node.signal(SIGINT);
  node.waitExit(20.0);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_safe_motion");
  g_port = test_support::nodeParam("/driver_node", "port");
  if (g_port.empty()) {
    std::fprintf(stderr, "the .test file must set /driver_node/port\n");
    return 1;
  }
  auto robot = makeBus(g_port);
  g_robot = robot.get();
  const int result = RUN_ALL_TESTS();
  g_robot = nullptr;
  return result;
}
