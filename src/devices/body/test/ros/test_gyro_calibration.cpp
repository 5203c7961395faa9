// imu/calibrate and ~imu/calibrate_on_start against simulated robots whose gyro has a bias of
// (0.02, -0.015, 0.03) rad/s (robot_sim's --gyro-bias): imu/data's angular velocity at rest is
// the bias until a calibration, within 1e-3 rad/s of zero after one; a calibration is refused
// while the base drives, when it starts driving during the averaging, with the e-stop engaged and
// without telemetry, and a refusal leaves the bias in force as it was; /diagnostics shows it.
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Bool.h>
#include <std_srvs/Trigger.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"
#include "support/test_helpers.h"

namespace {

namespace sim = serial_robot_driver::sim;
using test_support::waitFor;
using Rates = std::array<double, 3>;

constexpr Rates kBias{0.02, -0.015, 0.03};  // rad/s
// The simulated board reports whole LSB (1.0653 mrad/s): the bias it streams is off by up to half.
constexpr double kLsbTolerance = 0.0006;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// One driver_node (in namespace `ns`) and the simulated robot on its port.
struct Robot {
  Robot(ros::NodeHandle& nh, const std::string& ns, double telemetry_rate, bool servo_bus = false)
      : imu(nh, "/" + ns + "/imu/data", 500), diagnostics(nh, ns + "/driver_node"), ns_(ns) {
    sim::SimOptions options;
    options.link = test_support::nodeParam("/" + ns + "/driver_node", "port");
    options.device("servo_bus").enabled = servo_bus;
    serial_robot_driver::devices::body::sim::bodyConfig(options).telemetry_rate_hz = telemetry_rate;
    serial_robot_driver::devices::body::sim::bodyConfig(options).gyro_bias = kBias;
    robot = std::make_unique<sim::RobotSim>(options);
    robot->start();
    cmd_vel = nh.advertise<geometry_msgs::Twist>("/" + ns + "/cmd_vel", 10);
    trajectory = nh.advertise<trajectory_msgs::JointTrajectory>("/" + ns + "/joint_trajectory", 10);
    e_stop = nh.advertise<std_msgs::Bool>("/" + ns + "/e_stop", 10, true);
  }
  ~Robot() { robot->stop(); }

  std_srvs::Trigger::Response calibrate() {
    std_srvs::Trigger trigger;
    EXPECT_TRUE(ros::service::waitForService("/" + ns_ + "/imu/calibrate", ros::Duration(20)));
    EXPECT_TRUE(test_support::callService("/" + ns_ + "/imu/calibrate", trigger))
        << "imu/calibrate gave no answer";
    return trigger.response;
  }
  /// imu/data's mean angular velocity over the next `seconds`.
  Rates meanRate(double seconds) {
    const uint64_t from = imu.count();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    const auto messages = imu.since(from);
    EXPECT_GE(messages.size(), 20u) << "imu/data is not streaming";
    Rates sum{};
    for (const auto& msg : messages) {
      sum[0] += msg.angular_velocity.x;
      sum[1] += msg.angular_velocity.y;
      sum[2] += msg.angular_velocity.z;
    }
    for (double& axis : sum) axis /= messages.empty() ? 1.0 : static_cast<double>(messages.size());
    return sum;
  }
  /// Drives in an arc at 20 Hz for `seconds`; its cmd_vel timeout stops it afterwards.
  void drive(double seconds) {
    geometry_msgs::Twist twist;
    twist.linear.x = 0.1;
    twist.angular.z = 0.3;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      cmd_vel.publish(twist);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  /// Waits until the simulated wheels turn (the node obeys the cmd_vel being published).
  bool waitMoving() {
    return waitFor(
        [&] {
          return serial_robot_driver::devices::base::sim::baseStats(robot->stats())
                     .last_left_speed != 0;
        },
        10);
  }
  /// servo/spin of servo 1: mode 1 spins, mode 0 stops.
  bool spin(uint8_t mode) {
    serial_robot_driver::ServoSpin call;
    call.request.id = 1;
    call.request.mode = mode;
    call.request.speed_dps = 60;
    EXPECT_TRUE(ros::service::waitForService("/" + ns_ + "/servo/spin", ros::Duration(20)));
    return test_support::callService("/" + ns_ + "/servo/spin", call) && call.response.success;
  }
  /// Calls imu/calibrate until its answer contains `part` (each refusal answers at once).
  std_srvs::Trigger::Response calibrateUntil(const std::string& part, double seconds) {
    std_srvs::Trigger::Response response;
    waitFor(
        [&] {
          response = calibrate();
          return contains(response.message, part);
        },
        seconds);
    return response;
  }
  /// Waits until the simulated wheels stand still and the node's cmd_vel timeout has passed.
  bool waitStill() {
    const bool still = waitFor(
        [&] {
          const auto base = serial_robot_driver::devices::base::sim::baseStats(robot->stats());
          return base.last_left_speed == 0 && base.last_right_speed == 0;
        },
        10);
    // cmd_vel_timeout 0.5 s, then imu/calibrate's settle time of 1 s.
    std::this_thread::sleep_for(std::chrono::milliseconds(1700));
    return still;
  }
  std::string bodyValue(const std::string& key) const {
    return diagnostics.latest("body").value(key);
  }

  std::unique_ptr<sim::RobotSim> robot;
  test_support::TopicCounter<sensor_msgs::Imu> imu;
  test_support::DiagnosticsWatch diagnostics;
  ros::Publisher cmd_vel;
  ros::Publisher e_stop;
  ros::Publisher trajectory;

 private:
  std::string ns_;
};

void expectNear(const Rates& actual, const Rates& expected, double tolerance,
                const std::string& what) {
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(actual[i], expected[i], tolerance) << what << ", axis "
                                                   << "xyz"[i];
  }
}

class GyroCalibrationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    nh_ = std::make_unique<ros::NodeHandle>();
    manual_ = std::make_unique<Robot>(*nh_, "manual", 50.0);
    motion_ = std::make_unique<Robot>(*nh_, "motion", 50.0, true);
    on_start_ = std::make_unique<Robot>(*nh_, "on_start", 50.0);
    silent_ = std::make_unique<Robot>(*nh_, "silent", 0.0);
  }
  static void TearDownTestSuite() {
    manual_.reset();
    motion_.reset();
    on_start_.reset();
    silent_.reset();
    nh_.reset();
  }

  static std::unique_ptr<ros::NodeHandle> nh_;
  static std::unique_ptr<Robot> manual_, motion_, on_start_, silent_;
};

std::unique_ptr<ros::NodeHandle> GyroCalibrationTest::nh_;
std::unique_ptr<Robot> GyroCalibrationTest::manual_;
std::unique_ptr<Robot> GyroCalibrationTest::on_start_;
std::unique_ptr<Robot> GyroCalibrationTest::motion_;
std::unique_ptr<Robot> GyroCalibrationTest::silent_;

TEST_F(GyroCalibrationTest, CalibrateRemovesTheBiasAndRefusesWhenTheRobotIsNotStill) {
  Robot& robot = *manual_;
  ASSERT_TRUE(robot.imu.waitForCount(10, 30)) << "no imu/data from manual/driver_node";
  ASSERT_TRUE(waitFor([&] { return !robot.bodyValue("gyro bias").empty(); }, 10));
  EXPECT_EQ(robot.bodyValue("gyro bias"), "not calibrated");
  expectNear(robot.meanRate(1.0), kBias, kLsbTolerance, "before calibration: the bias");

  // Driving: refused, nothing in force changes.
  std::atomic<bool> driving{true};
  std::thread driver([&] {
    while (driving) robot.drive(0.1);
  });
  const bool moved = robot.waitMoving();
  std_srvs::Trigger::Response response = robot.calibrate();
  driving = false;
  driver.join();
  ASSERT_TRUE(moved) << "the simulated base never drove";
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "not held still (base: cmd_vel of 0.1 m/s, 0.3 rad/s"))
      << response.message;
  EXPECT_TRUE(contains(response.message, "unchanged: not calibrated")) << response.message;
  ASSERT_TRUE(robot.waitStill());

  // The base starts driving during the averaging: refused.
  std::thread late_driver([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // of 2 s of averaging
    robot.drive(0.5);
  });
  response = robot.calibrate();
  late_driver.join();
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "moved during the averaging: base: cmd_vel"))
      << response.message;
  ASSERT_TRUE(robot.waitStill());

  // E-stop engaged: refused.
  ASSERT_TRUE(test_support::setEStopAndWait(robot.e_stop, robot.diagnostics, true, 10));
  response = robot.calibrate();
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "the e-stop is engaged")) << response.message;
  ASSERT_TRUE(waitFor([&] { return !robot.bodyValue("gyro calibration refused").empty(); }, 5));
  EXPECT_EQ(robot.diagnostics.latest("body").level, diagnostic_msgs::DiagnosticStatus::WARN);
  ASSERT_TRUE(test_support::setEStopAndWait(robot.e_stop, robot.diagnostics, false, 10));
  // Also the settle time (1 s) after the release.
  expectNear(robot.meanRate(1.2), kBias, kLsbTolerance, "refusals changed nothing");

  // Still: the bias is found and subtracted from then on.
  response = robot.calibrate();
  ASSERT_TRUE(response.success) << response.message;
  EXPECT_TRUE(contains(response.message, "gyro bias (0.02")) << response.message;
  EXPECT_TRUE(contains(response.message, "deg/s from ")) << response.message;
  EXPECT_TRUE(contains(response.message, "before: not calibrated")) << response.message;
  expectNear(robot.meanRate(1.0), {0, 0, 0}, 1e-3, "after imu/calibrate");
  ASSERT_TRUE(waitFor([&] { return contains(robot.bodyValue("gyro bias"), "(0.02"); }, 5))
      << robot.bodyValue("gyro bias");
  EXPECT_TRUE(contains(robot.bodyValue("gyro bias"), "rad/s ="));
  EXPECT_TRUE(contains(robot.bodyValue("gyro bias calibrated"), "by imu/calibrate at "));
  ASSERT_TRUE(waitFor([&] { return robot.bodyValue("gyro calibration refused").empty(); }, 5))
      << "a good calibration clears the warning";

  // A refusal keeps the bias in force.
  std::atomic<bool> driving_again{true};
  std::thread driver_again([&] {
    while (driving_again) robot.drive(0.1);
  });
  const bool moved_again = robot.waitMoving();
  response = robot.calibrate();
  driving_again = false;
  driver_again.join();
  ASSERT_TRUE(moved_again) << "the simulated base never drove";
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "unchanged: (0.02")) << response.message;
  ASSERT_TRUE(robot.waitStill());
  expectNear(robot.meanRate(1.0), {0, 0, 0}, 1e-3, "after a refused calibration");
}

// Not only the base: a body trajectory and a spinning bus servo are motion too, and a motion that
// just ended needs its settle time before the gyro is averaged.
TEST_F(GyroCalibrationTest, RefusedDuringABodyTrajectoryAndABusSpinAndRightAfterTheSpinStops) {
  Robot& robot = *motion_;
  ASSERT_TRUE(robot.imu.waitForCount(10, 30)) << "no imu/data from motion/driver_node";
  ASSERT_TRUE(waitFor([&] { return robot.trajectory.getNumSubscribers() > 0; }, 10));
  trajectory_msgs::JointTrajectory slow;  // 3 s for 0.3 rad: a slow, smooth motion
  slow.joint_names = {"joint_1"};
  slow.points.resize(1);
  slow.points[0].positions = {0.3};
  slow.points[0].time_from_start = ros::Duration(3.0);
  robot.trajectory.publish(slow);
  std_srvs::Trigger::Response response = robot.calibrateUntil("not held still (", 5);
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "body: joint command written") ||
              contains(response.message, "trajectories: trajectory in progress ('joint_1')"))
      << response.message;
  // The trajectory ends (3 s), and its last joint command counts as motion for 0.5 s: then the
  // settle time, naming what moved.
  response = robot.calibrateUntil("the robot was moving until", 10);
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "(body: joint command written")) << response.message;

  ASSERT_TRUE(robot.spin(1));
  response = robot.calibrateUntil("servo_bus: servo(s) 1 set moving", 10);
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "not held still (servo_bus: servo(s) 1 set moving"))
      << response.message;
  // Stopped: refused at once all the same, for the settle time after the motion.
  ASSERT_TRUE(robot.spin(0));
  response = robot.calibrate();
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "(servo_bus: servo(s) 1 set moving")) << response.message;
  EXPECT_TRUE(contains(response.message, "it must be still for 1 s after the last motion"))
      << response.message;
  EXPECT_TRUE(contains(response.message, "unchanged: not calibrated")) << response.message;
  // Then it calibrates.
  response = robot.calibrateUntil("gyro bias (0.02", 15);
  EXPECT_TRUE(response.success) << response.message;
}

TEST_F(GyroCalibrationTest, CalibrateOnStartRemovesTheBiasWithoutAServiceCall) {
  Robot& robot = *on_start_;
  ASSERT_TRUE(robot.imu.waitForCount(10, 30)) << "no imu/data from on_start/driver_node";
  ASSERT_TRUE(waitFor(
      [&] { return contains(robot.bodyValue("gyro bias calibrated"), "by calibrate_on_start"); },
      20))
      << robot.bodyValue("gyro bias calibrated");
  expectNear(robot.meanRate(1.0), {0, 0, 0}, 1e-3, "after calibrate_on_start");
  EXPECT_TRUE(contains(robot.bodyValue("gyro bias"), "(0.02")) << robot.bodyValue("gyro bias");
}

TEST_F(GyroCalibrationTest, CalibrateWithoutTelemetryIsRefused) {
  Robot& robot = *silent_;
  const std_srvs::Trigger::Response response = robot.calibrate();
  EXPECT_FALSE(response.success);
  EXPECT_TRUE(contains(response.message, "no IMU telemetry")) << response.message;
  EXPECT_TRUE(contains(response.message, "unchanged: not calibrated")) << response.message;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_gyro_calibration");
  return RUN_ALL_TESTS();
}
