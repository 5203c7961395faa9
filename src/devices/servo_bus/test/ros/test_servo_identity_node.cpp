// Each configured servo's identity checked at start, and servo/info (servo_identity.test):
// driver_node polls servos 1, 2 and 3 of a simulated bus (sim::RobotSim in this process, servos
// 1..4) with ~servo_bus/expected_type 257. Servo 2 reports servo_type 300, servo 3 has
// response_switch 1, servo 4 (not configured) firmware_version 300. Checked through
// /diagnostics and servo/info. No timing assertions: every wait has a generous deadline.
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cstdio>
#include <string>

#include "serial_robot_driver/ServoInfo.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
using serial_robot_driver::ServoInfo;
using test_support::DiagnosticsWatch;
using test_support::waitFor;

constexpr double kWaitSeconds = 20.0;
// What every simulated servo reports unless told otherwise (servo_bus_sim.h).
constexpr uint16_t kSimType = 257;
constexpr uint16_t kSimFirmware = 258;
constexpr uint32_t kSimSerialBase = 0x53520000;

sim::RobotSim* g_robot = nullptr;

/// The latest "servo_bus servo <id>" status once its identity has been read and its health poll
/// answered (waits for both: the node may have polled before the simulator was up).
DiagnosticsWatch::Status identifiedStatus(const DiagnosticsWatch& diagnostics, int id) {
  const std::string name = "servo_bus servo " + std::to_string(id);
  EXPECT_TRUE(waitFor(
      [&] {
        const DiagnosticsWatch::Status status = diagnostics.latest(name);
        return !status.value("servo_type").empty() && status.flag("online");
      },
      kWaitSeconds))
      << name << " shows no identity";
  return diagnostics.latest(name);
}

ServoInfo info(uint8_t id) {
  ServoInfo srv;
  srv.request.id = id;
  EXPECT_TRUE(test_support::callService("servo/info", srv));
  return srv;
}

TEST(ServoIdentity, AnotherModelAndAQueuingServoAreWarnedInDiagnosticsTheOthersNot) {
  ros::NodeHandle nh;
  const DiagnosticsWatch diagnostics(nh, "driver_node");

  const DiagnosticsWatch::Status plain = identifiedStatus(diagnostics, 1);
  EXPECT_EQ(plain.level, diagnostic_msgs::DiagnosticStatus::OK) << plain.message;
  EXPECT_EQ(plain.value("servo_type"), std::to_string(kSimType));
  EXPECT_EQ(plain.value("firmware_version"), std::to_string(kSimFirmware));
  EXPECT_EQ(plain.value("serial_number"), std::to_string(kSimSerialBase + 1));
  EXPECT_EQ(plain.value("response_switch"), "0");

  const DiagnosticsWatch::Status other_model = identifiedStatus(diagnostics, 2);
  EXPECT_EQ(other_model.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(other_model.message.find("servo 2: servo_type 300 is not the expected 257"),
            std::string::npos)
      << other_model.message;
  EXPECT_EQ(other_model.value("servo_type"), "300");

  const DiagnosticsWatch::Status queuing = identifiedStatus(diagnostics, 3);
  EXPECT_EQ(queuing.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(queuing.message.find("servo 3: response_switch is 1"), std::string::npos)
      << queuing.message;
  EXPECT_NE(queuing.message.find("a stop cannot interrupt a motion already queued"),
            std::string::npos)
      << queuing.message;
  EXPECT_EQ(queuing.value("response_switch"), "1");
}

TEST(ServoIdentity, InfoReadsAConfiguredServo) {
  ASSERT_TRUE(ros::service::waitForService("servo/info", ros::Duration(kWaitSeconds)));
  const ServoInfo srv = info(3);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.servo_type, kSimType);
  EXPECT_EQ(srv.response.firmware_version, kSimFirmware);
  EXPECT_EQ(srv.response.serial_number, kSimSerialBase + 3);
  EXPECT_EQ(srv.response.response_switch, 1);
  EXPECT_NE(srv.response.message.find("WARNING servo 3: response_switch is 1"), std::string::npos)
      << srv.response.message;
  EXPECT_NE(srv.response.message.find("over_temperature"), std::string::npos)
      << srv.response.message;
}

TEST(ServoIdentity, InfoReadsAServoThatIsNotConfigured) {
  ASSERT_TRUE(ros::service::waitForService("servo/info", ros::Duration(kWaitSeconds)));
  const ServoInfo srv = info(4);
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_EQ(srv.response.servo_type, kSimType);
  EXPECT_EQ(srv.response.firmware_version, 300);
  EXPECT_EQ(srv.response.serial_number, kSimSerialBase + 4);
  EXPECT_EQ(srv.response.response_switch, 0);
  EXPECT_EQ(srv.response.message.find("WARNING"), std::string::npos) << srv.response.message;
}

TEST(ServoIdentity, InfoFailsCleanlyForAnAbsentServo) {
  ASSERT_TRUE(ros::service::waitForService("servo/info", ros::Duration(kWaitSeconds)));
  const ServoInfo srv = info(9);
  EXPECT_FALSE(srv.response.success);
  EXPECT_EQ(srv.response.message.rfind("servo 9's identity could not be read: ", 0), 0u)
      << srv.response.message;
  EXPECT_EQ(srv.response.servo_type, 0);
  EXPECT_EQ(srv.response.serial_number, 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_identity");
  const std::string port = test_support::nodeParam("/driver_node", "port");
  if (port.empty()) {
    std::fprintf(stderr, "the .test file must set /driver_node/port\n");
    return 1;
  }
  sim::SimOptions options;
  options.device("base").enabled = false;
  options.device("body").enabled = false;
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).servo_ids = {1, 2, 3, 4};
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).servo_type = {{2, 300}};
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).response_switch = {{3, 1}};
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).firmware_version = {
      {4, 300}};
  options.device("servo_bus").link = port;
  return test_support::runAllTestsWithSim(options, &g_robot);
}
