#include "serial_robot_driver/devices/base/ros/calibrate_base_client.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Twist.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/Bool.h>

#include "serial_robot_driver/WheelCommand.h"

namespace serial_robot_driver::devices::base::ros {

std::optional<std::string> findCalibrationDriver(const std::string& named,
                                                 const std::atomic<int>& stop_signal,
                                                 std::string* why) {
  if (!named.empty()) return ::ros::names::resolve(named);
  const std::string topic = ::ros::names::resolve("wheel_command");
  const ::ros::WallTime deadline = ::ros::WallTime::now() + ::ros::WallDuration(5.0);
  for (; ::ros::WallTime::now() < deadline && stop_signal == 0 && ::ros::ok();
       ::ros::WallDuration(0.01).sleep()) {
    XmlRpc::XmlRpcValue args, result, payload;
    args[0] = ::ros::this_node::getName();
    if (!::ros::master::execute("getSystemState", args, result, payload, false)) continue;
    for (int i = 0; i < payload[0].size(); ++i) {  // payload[0]: [topic, [publishers]]
      if (std::string(payload[0][i][0]) != topic) continue;
      if (payload[0][i][1].size() > 1) {
        *why = "several nodes publish " + topic + ": name the driver with --node";
        return std::nullopt;
      }
      if (payload[0][i][1].size() == 1) return std::string(payload[0][i][1][0]);
    }
  }
  *why = noCalibrationDriverText(stop_signal, ::ros::ok(), topic);
  return std::nullopt;
}

CalibrationTopics::CalibrationTopics(TurnCalibrationRun& run) {
  cmd_vel_ = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 10);
  imu_ = nh_.subscribe<sensor_msgs::Imu>(
      "imu/data", 100, [&run](const sensor_msgs::Imu::ConstPtr& msg) {
        run.addImuRate(msg->header.stamp.toSec(), msg->angular_velocity.z);
      });
  frames_ =
      nh_.subscribe<WheelCommand>("wheel_command", 100, [&run](const WheelCommand::ConstPtr& msg) {
        run.addWheelFrame(msg->header.stamp.toSec(), msg->left_ticks, msg->right_ticks);
      });
  diagnostics_ = nh_.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20,
      [&run, name = run.eStopStatusName()](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
        for (const auto& status : msg->status) {
          if (status.name != name) continue;
          for (const auto& value : status.values) run.setEStopStatusValue(value.key, value.value);
        }
      });
  // The driver's own input: every engagement published on it, however short (the once-a-second
  // status above would miss one shorter than its period; its count catches what this missed).
  e_stop_ = nh_.subscribe<std_msgs::Bool>(
      "e_stop", 10, [&run](const std_msgs::Bool::ConstPtr& msg) { run.setEStopEngaged(msg->data); },
      ::ros::VoidConstPtr(), ::ros::TransportHints().tcpNoDelay());
}

void CalibrationTopics::command(const BaseTwist& twist) {
  geometry_msgs::Twist msg;
  msg.linear.x = twist.linear;
  msg.angular.z = twist.angular;
  cmd_vel_.publish(msg);
}

}  // namespace serial_robot_driver::devices::base::ros
