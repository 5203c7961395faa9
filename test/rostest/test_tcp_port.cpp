// driver_node on a port reached over TCP (tcp_port.test): cmd_vel reaches the simulated base served
// by sim::RobotSim on a loopback TCP socket; when the simulator drops the connection and closes its
// listener (--unplug-every) the node reports the port down and writes nothing, then reconnects,
// resets the base and drives again, as with a serial cable pulled and plugged back.
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <signal.h>

#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/process_support.h"
#include "support/ros_test_support.h"
#include "support/test_helpers.h"

namespace {

namespace sim = serial_robot_driver::sim;
using serial_robot_driver::devices::base::sim::baseStats;
using test_support::DiagnosticsWatch;

constexpr double kWaitSeconds = 20.0;  // generous: the machine may be busy

sim::SimOptions tcpBaseOnly() {
  sim::SimOptions options;
  options.link = "tcp://127.0.0.1:0";  // a free port, read back from ports()
  options.device("body").enabled = false;
  options.device("servo_bus").enabled = false;
  // The server's line goes away every 10 s for 4 s: long enough for two diagnostics while down.
  options.faults.unplug_every_s = 10.0;
  options.faults.unplug_duration_s = 4.0;
  return options;
}

TEST(TcpPort, DrivesOverTcpAndRecoversAfterTheServerDropsTheConnection) {
  sim::RobotSim robot(tcpBaseOnly());
  robot.start();
  const std::string url = robot.ports().at(0).slave_path;
  ASSERT_EQ(url.rfind("tcp://127.0.0.1:", 0), 0u) << url;

  const std::string driver = test_support::findDriverNode();
  ASSERT_FALSE(driver.empty());
  test_support::ChildProcess node(
      driver, {"__ns:=/tcp", "__name:=driver_node", "_port:=" + url, "_reconnect_interval:=0.2",
               "_body/enabled:=false", "_servo_bus/enabled:=false", "_base/cmd_vel_timeout:=0.5"});
  ASSERT_TRUE(node.started());
  ros::NodeHandle nh("tcp");
  ros::Publisher cmd_vel = nh.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  DiagnosticsWatch diagnostics(nh, "tcp/driver_node");
  const std::string port_status = "port " + url;
  geometry_msgs::Twist forward;
  forward.linear.x = 0.3;
  // Streams cmd_vel while waiting for `done` (the node stops the base 0.5 s after the last one).
  const auto drivingUntil = [&](const std::function<bool()>& done) {
    return test_support::waitFor(
        [&] {
          cmd_vel.publish(forward);
          return done();
        },
        kWaitSeconds);
  };
  const auto wheelsTurn = [&] { return baseStats(robot.stats()).last_left_speed > 0; };

  ASSERT_TRUE(drivingUntil(wheelsTurn)) << "cmd_vel never reached the base\n" << node.output();
  const uint64_t resets_before = baseStats(robot.stats()).resets;

  // The server drops the connection: the node reports the port down and writes nothing.
  ASSERT_TRUE(drivingUntil([&] { return robot.stats().unplugs >= 1; }));
  const auto down = diagnostics.waitFor(
      port_status, 0, [](const DiagnosticsWatch::Status& s) { return !s.flag("connected"); },
      [] { return ros::ok(); }, kWaitSeconds);
  ASSERT_TRUE(down.has_value()) << "the port was never reported down\n" << node.output();
  const auto still_down = diagnostics.waitFor(
      port_status, down->received, [](const DiagnosticsWatch::Status&) { return true; },
      [] { return ros::ok(); }, kWaitSeconds);
  ASSERT_TRUE(still_down.has_value());
  if (!still_down->flag("connected")) {
    EXPECT_EQ(still_down->number("frames out"), down->number("frames out"))
        << "frames written while the port was down";
  }

  // The server is back: the node reconnects, resets the base first and drives again.
  ASSERT_TRUE(drivingUntil([&] { return robot.stats().replugs >= 1; }));
  const auto up = diagnostics.waitFor(
      port_status, down->received,
      [](const DiagnosticsWatch::Status& s) { return s.flag("connected"); },
      [] { return ros::ok(); }, kWaitSeconds);
  ASSERT_TRUE(up.has_value()) << "the port never came back\n" << node.output();
  EXPECT_GE(up->number("connects"), 2u);
  EXPECT_TRUE(drivingUntil([&] {
    return baseStats(robot.stats()).resets > resets_before && wheelsTurn();
  })) << "no Reset and motion after the reconnect\n"
      << node.output();

  node.signal(SIGTERM);
  EXPECT_TRUE(node.waitExit(10.0).has_value()) << "driver_node did not exit on SIGTERM";
  robot.stop();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_tcp_port");
  return RUN_ALL_TESTS();
}
