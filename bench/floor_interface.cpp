#include "floor_interface.h"

#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <string>

#include "serial_robot_driver/FootPressure.h"
#include "serial_robot_driver/Telemetry.h"
#include "serial_robot_driver/WheelCommand.h"

namespace floor_bench {

namespace {
template <typename M>
ros::Subscriber ignore(ros::NodeHandle& nh, const std::string& topic) {
  const boost::function<void(const typename M::ConstPtr&)> nothing = [](const auto&) {};
  return nh.subscribe<M>(topic, 10, nothing);
}
}  // namespace

FloorInterface::FloorInterface(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  publishers_ = {
      nh.advertise<sensor_msgs::BatteryState>("battery", 1, true),
      nh.advertise<serial_robot_driver::FootPressure>("foot_pressure", 10),
      nh.advertise<sensor_msgs::JointState>("servo_states", 10),
      nh.advertise<serial_robot_driver::Telemetry>("telemetry", 10),
      nh.advertise<serial_robot_driver::WheelCommand>("wheel_command", 10),
  };
  subscribers_ = {
      ignore<std_msgs::Bool>(nh, "e_stop"),
      ignore<sensor_msgs::JointState>(nh, "joint_commands"),
      ignore<trajectory_msgs::JointTrajectory>(nh, "joint_trajectory"),
      ignore<sensor_msgs::JointState>(nh, "servo_commands"),
  };
  // driver_node's four tuning groups; one config type serves for all (the topics are the same
  // two per server, and their messages are sent only on connection and on a change).
  for (const char* group : {"base", "imu", "servo_bus", "trajectory"}) {
    tuning_.push_back(std::make_unique<TuningServer>(ros::NodeHandle(pnh, group)));
  }
  // Goals are refused: the floor moves nothing; the status still goes out at 5 Hz.
  action_ = std::make_unique<ActionServer>(
      nh, "follow_joint_trajectory", [](ActionServer::GoalHandle goal) { goal.setRejected(); },
      false);
  action_->start();
}

}  // namespace floor_bench
