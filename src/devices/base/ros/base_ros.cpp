#include "serial_robot_driver/devices/base/ros/base_ros.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/ros/base_conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/publish_wanted.h"
#include "serial_robot_driver/ros/trigger_service.h"

namespace serial_robot_driver::devices::base::ros {

BaseRos::BaseRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, BaseDevice& device)
    : device_(device),
      arrival_stamps_(params),
      tf_pub_(device.params().publish_tf ? advertiseTf() : ros_layer::CountedPublisher()) {
  odom_pub_ = ros_layer::advertiseCounted<nav_msgs::Odometry>(nh, "odom", 50);
  wheel_command_pub_ =
      ros_layer::advertiseCounted<serial_robot_driver::WheelCommand>(nh, "wheel_command", 50);
  battery_pub_ = ros_layer::advertiseCounted<sensor_msgs::BatteryState>(nh, "battery",
                                                                        params.publisherQueue(5));
  wheel_states_pub_ = ros_layer::advertiseCounted<sensor_msgs::JointState>(nh, "wheel_states", 50);
  device.addOutputs(outputs());

  core::InputRefusals& refusals = device.inputRefusals();
  // tcpNoDelay: a cmd_vel must not sit in Nagle's buffer; its callback writes it at once.
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
    if (!ros_layer::wanted(battery_pub_)) return;
    battery_pub_.publish(toBatteryState(reading, arrival_stamps_(arrival)));
  };
  return outputs;
}

void BaseRos::publishWheelCommand(const WheelFrameSent& sent) {
  if (!ros_layer::wanted(wheel_command_pub_)) return;  // 50 Hz: skip work nobody reads
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
  // Called on the control loop's thread once per tick; never touches the port. What nobody
  // subscribes to is not built (/tf included: it goes out whenever anyone listens to /tf). Stamped
  // with the tick's time, as on every front end (the DDS one gives the same sample that stamp).
  const ::ros::Time stamp = arrival_stamps_(sample.time);
  const bool publish_tf = device_.tuned()->publish_tf;
  // ~base/publish_tf switched on at runtime: /tf is advertised from then on.
  if (publish_tf && !tf_pub_) tf_pub_ = advertiseTf();
  const bool odom_wanted = ros_layer::wanted(odom_pub_);
  const bool tf_wanted = publish_tf && ros_layer::wanted(tf_pub_);
  const bool wheels_wanted = ros_layer::wanted(wheel_states_pub_);
  // Every message is built before the first goes out: roscpp's sending thread, woken by the first,
  // then finds the others queued too instead of being woken once more for each.
  if (odom_wanted || tf_wanted) {
    const BaseParams& started = device_.params();
    fillOdometry(sample, {started.odom_frame, started.base_frame}, stamp, &odom_);
  }
  if (wheels_wanted) buildWheelStates(sample, stamp);
  if (tf_wanted) buildTf(odom_, sample);
  if (odom_wanted) odom_pub_.publish(odom_);
  if (wheels_wanted) wheel_states_pub_.publish(wheel_states_);
  if (tf_wanted) tf_pub_.publish(tf_);
}

void BaseRos::buildTf(const nav_msgs::Odometry& odom, const OdometrySample& sample) {
  tf_.transforms.resize(1);
  geometry_msgs::TransformStamped& transform = tf_.transforms[0];
  transform.header = odom.header;
  transform.child_frame_id = odom.child_frame_id;
  transform.transform.translation.x = sample.pose.x;
  transform.transform.translation.y = sample.pose.y;
  transform.transform.translation.z = 0.0;
  transform.transform.rotation = odom.pose.pose.orientation;
}

ros_layer::CountedPublisher BaseRos::advertiseTf() {
  // As tf2_ros::TransformBroadcaster advertises it, with a publisher whose subscribers we can
  // count.
  ::ros::NodeHandle global;
  return ros_layer::advertiseCounted<tf2_msgs::TFMessage>(global, "/tf", 100);
}

void BaseRos::buildWheelStates(const OdometrySample& sample, const ::ros::Time& stamp) {
  // The wheels' angles as robot_state_publisher wants them: the same accepted motion as odom.
  const BaseParams& started = device_.params();
  fillWheelStates(sample, started.base_frame, started.left_wheel_joint, started.right_wheel_joint,
                  stamp, &wheel_states_);
}

}  // namespace serial_robot_driver::devices::base::ros
