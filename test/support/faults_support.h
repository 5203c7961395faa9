// What the faults.test tests share: the wheel-speed limits and extreme values, and the
// ExtremeInputs fixture: /extreme/driver_node with the simulator library in this process as its
// robot (started once for all Extreme* tests), which must stay alive and never be restarted.
//
// The machine may be busy (2 shared cores): the tests count frames and use generous deadlines.
#pragma once

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

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
#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/fake_device.h"
#include "support/ros_test_support.h"

namespace faults_test {

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
// Extreme inputs
// =================================================================================================

/// The simulated robot of /extreme/driver_node, started once for all Extreme* tests.
inline sim::RobotSim& extremeRobot() {
  static std::unique_ptr<sim::RobotSim> robot = [] {
    sim::SimOptions options;
    options.link = test_support::nodeParam("/extreme/driver_node", "port");
    auto created = std::make_unique<sim::RobotSim>(options);
    created->start();
    return created;
  }();
  return *robot;
}

inline int extremePid() {
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

}  // namespace faults_test
