#include "serial_robot_driver/devices/base/ros/base_ros.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>

#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/ros/base_conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/trigger_service.h"

namespace serial_robot_driver::devices::base::ros {

BaseRos::BaseRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, BaseDevice& device)
    : device_(device),
      arrival_stamps_(params),
      tf_broadcaster_(device.params().publish_tf ? std::make_unique<tf2_ros::TransformBroadcaster>()
                                                 : nullptr) {
  odom_pub_ = nh.advertise<nav_msgs::Odometry>("odom", 50);
  wheel_command_pub_ = nh.advertise<serial_robot_driver::WheelCommand>("wheel_command", 50);
  battery_pub_ = nh.advertise<sensor_msgs::BatteryState>("battery", params.publisherQueue(5));
  wheel_states_pub_ = nh.advertise<sensor_msgs::JointState>("wheel_states", 50);
  device.addOutputs(outputs());

  core::InputRefusals& refusals = device.inputRefusals();
  // tcpNoDelay: a cmd_vel must not sit in Nagle's buffer; the loop puts it on the wire at once.
  const ros_layer::SubscriberCallback<geometry_msgs::Twist> on_cmd_vel =
      [this](const geometry_msgs::Twist::ConstPtr& msg) {
        device_.commandTwist({msg->linear.x, msg->angular.z});
      };
  cmd_vel_sub_ = nh.subscribe<geometry_msgs::Twist>(
      "cmd_vel", 10, ros_layer::guardedSubscriber(refusals, "cmd_vel", on_cmd_vel),
      ::ros::VoidConstPtr(), ::ros::TransportHints().tcpNoDelay());
  reset_srv_ =
      ros_layer::advertiseTrigger(nh, refusals, "base/reset", [&device] { return device.reset(); });
  reset_odometry_srv_ = ros_layer::advertiseTrigger(nh, refusals, "base/reset_odometry",
                                                    [&device] { return device.resetOdometry(); });
  clear_encoders_srv_ = ros_layer::advertiseTrigger(nh, refusals, "base/clear_encoders",
                                                    [&device] { return device.clearEncoders(); });
}

BaseOutputs BaseRos::outputs() {
  BaseOutputs outputs;
  outputs.wheel_frame = [this](const WheelFrameSent& sent) { publishWheelCommand(sent); };
  outputs.odometry = [this](const OdometrySample& sample) { publishOdometry(sample); };
  outputs.battery = [this](const BatteryReading& reading, core::Clock::time_point arrival) {
    battery_pub_.publish(toBatteryState(reading, arrival_stamps_(arrival)));
  };
  return outputs;
}

void BaseRos::publishWheelCommand(const WheelFrameSent& sent) {
  if (wheel_command_pub_.getNumSubscribers() == 0) return;  // 50 Hz: skip work nobody reads
  serial_robot_driver::WheelCommand msg;
  msg.header.stamp = ::ros::Time::now();
  msg.left_ticks = sent.ticks.left;
  msg.right_ticks = sent.ticks.right;
  msg.seq = sent.seq;
  msg.reset_before = sent.reset_before;
  msg.left_speed = sent.speeds.x();
  msg.right_speed = sent.speeds.y();
  wheel_command_pub_.publish(msg);
}

void BaseRos::publishOdometry(const OdometrySample& sample) {
  // Called on the control loop's thread once per tick; never touches the port.
  const ::ros::Time stamp = ::ros::Time::now();
  const BaseParams& started = device_.params();
  const nav_msgs::Odometry odom =
      toOdometry(sample, {started.odom_frame, started.base_frame}, stamp);
  odom_pub_.publish(odom);
  publishWheelStates(sample, stamp);

  if (!device_.tuned()->publish_tf) return;
  // ~base/publish_tf switched on at runtime: /tf is advertised from then on.
  if (!tf_broadcaster_) tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  geometry_msgs::TransformStamped transform;
  transform.header = odom.header;
  transform.child_frame_id = odom.child_frame_id;
  transform.transform.translation.x = sample.pose.x;
  transform.transform.translation.y = sample.pose.y;
  transform.transform.rotation = odom.pose.pose.orientation;
  tf_broadcaster_->sendTransform(transform);
}

void BaseRos::publishWheelStates(const OdometrySample& sample, const ::ros::Time& stamp) {
  // The wheels' angles as robot_state_publisher wants them: the same accepted motion as odom.
  const BaseParams& started = device_.params();
  wheel_states_pub_.publish(toWheelStates(sample, started.base_frame, started.left_wheel_joint,
                                          started.right_wheel_joint, stamp));
}

}  // namespace serial_robot_driver::devices::base::ros
