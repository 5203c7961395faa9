// The ROS interface fuzzer's inputs (test_ros_interface_fuzz.cpp): seeded extreme values, and
// messages and service requests of driver_node's interface built from a valid one with one to
// three fields at their extremes.
#pragma once

#include <actionlib_msgs/GoalID.h>
#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryActionGoal.h"

namespace ros_fuzz {

namespace srd = serial_robot_driver;

constexpr std::size_t kHugeArray = 100000;  // elements: bounded, not gigabytes
constexpr std::size_t kLongString = 10000;  // characters, only in short arrays

/// Extreme values of every kind a field can have, drawn from one seeded generator.
class Extremes {
 public:
  explicit Extremes(uint64_t seed) : rng_(seed) {}

  std::size_t pick(std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }

  double real() {
    const double kMax = std::numeric_limits<double>::max();
    const double kInf = std::numeric_limits<double>::infinity();
    const double values[] = {0.0,
                             -0.0,
                             1.0,
                             -1.0,
                             std::numeric_limits<double>::quiet_NaN(),
                             kInf,
                             -kInf,
                             1e308,
                             -1e308,
                             kMax,
                             -kMax,
                             std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::denorm_min(),
                             0.5,
                             3.2,
                             -3.2};
    if (chance(0.3)) return std::uniform_real_distribution<double>(-4.0, 4.0)(rng_);
    return values[pick(sizeof(values) / sizeof(values[0]))];
  }
  template <typename Int>
  Int integer() {
    using L = std::numeric_limits<Int>;
    const Int values[] = {0,
                          1,
                          2,
                          L::max(),
                          static_cast<Int>(L::max() - 1),
                          L::min(),
                          static_cast<Int>(L::min() + 1),
                          static_cast<Int>(255),
                          static_cast<Int>(254)};
    if (chance(0.3)) return static_cast<Int>(rng_());
    return values[pick(sizeof(values) / sizeof(values[0]))];
  }
  std::size_t size() {
    const std::size_t sizes[] = {0, 1, 2, 3, 7, 300, kHugeArray};
    return sizes[pick(sizeof(sizes) / sizeof(sizes[0]))];
  }
  /// A name: one of `known` (duplicates come from drawing twice), an unknown one, empty, long.
  std::string name(const std::vector<std::string>& known, bool short_only) {
    switch (pick(6)) {
      case 0:
        return "";
      case 1:
        return "no_such_joint";
      case 2:
        return short_only ? "servo_999" : std::string(kLongString, 'x');
      case 3:
        return "servo_" + std::to_string(integer<uint8_t>());
      default:
        return known[pick(known.size())];
    }
  }
  std::vector<std::string> names(std::size_t n, const std::vector<std::string>& known) {
    std::vector<std::string> out(n);
    for (std::string& each : out) each = name(known, n > 3);
    return out;
  }
  std::vector<double> reals(std::size_t n) {
    std::vector<double> out(n);
    for (double& each : out)
      each = chance(0.8) ? std::uniform_real_distribution<double>(-1, 1)(rng_) : real();
    return out;
  }
  /// A stamp: zero, now, just past, ahead within and beyond max_start_delay, the far future
  /// (4e9 s), the ends of uint32, an unnormalised nsec.
  ros::Time stamp() {
    const ros::Time now = ros::Time::now();
    ros::Time t;
    switch (pick(9)) {
      case 0:
        return ros::Time();
      case 1:
        return now;
      case 2:
        return now - ros::Duration(1.0);
      case 3:
        return now + ros::Duration(5.0);
      case 4:
        return now + ros::Duration(11.0);
      case 5:
        t.sec = 4000000000u;
        return t;
      case 6:
        t.sec = t.nsec = std::numeric_limits<uint32_t>::max();
        return t;
      case 7:
        t.nsec = 1;
        return t;
      default:
        t.sec = now.sec;
        t.nsec = std::numeric_limits<uint32_t>::max();
        return t;
    }
  }
  /// A duration: zero, negative, enormous, the ends of int32, unnormalised.
  ros::Duration duration() {
    ros::Duration d;
    switch (pick(6)) {
      case 0:
        return ros::Duration(0.0);
      case 1:
        d.sec = -1;
        return d;
      case 2:
        d.sec = std::numeric_limits<int32_t>::max();
        return d;
      case 3:
        d.sec = std::numeric_limits<int32_t>::min();
        return d;
      case 4:
        d.nsec = std::numeric_limits<int32_t>::max();
        return d;
      default:
        d.nsec = std::numeric_limits<int32_t>::min();
        return d;
    }
  }

 private:
  std::mt19937_64 rng_;
};

/// Publishers of every subscribed topic (e_stop is the fuzzer's own switch).
struct Topics {
  explicit Topics(ros::NodeHandle& nh)
      : cmd_vel(nh.advertise<geometry_msgs::Twist>("cmd_vel", 100)),
        joint_commands(nh.advertise<sensor_msgs::JointState>("joint_commands", 100)),
        servo_commands(nh.advertise<sensor_msgs::JointState>("servo_commands", 100)),
        joint_trajectory(nh.advertise<trajectory_msgs::JointTrajectory>("joint_trajectory", 100)),
        goal(nh.advertise<srd::FollowJointTrajectoryActionGoal>("follow_joint_trajectory/goal",
                                                                100)),
        cancel(nh.advertise<actionlib_msgs::GoalID>("follow_joint_trajectory/cancel", 100)) {}
  bool connected() const {
    for (const ros::Publisher* p :
         {&cmd_vel, &joint_commands, &servo_commands, &joint_trajectory, &goal, &cancel}) {
      if (p->getNumSubscribers() == 0) return false;
    }
    return true;
  }
  ros::Publisher cmd_vel, joint_commands, servo_commands, joint_trajectory, goal, cancel;
};

/// One input to a random topic or service; returns what it was sent to.
void fuzzOne(Extremes& x, Topics& topics);

}  // namespace ros_fuzz
