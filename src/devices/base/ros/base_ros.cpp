#include "serial_robot_driver/devices/base/ros/base_ros.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/BatteryState.h>
#include <sensor_msgs/JointState.h>
#include <tf2_msgs/TFMessage.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/devices/base/base_status.h"
#include "serial_robot_driver/devices/base/ros/base_conversions.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/publish_wanted.h"

namespace serial_robot_driver::devices::base::ros {

BaseEvents BaseRos::events() {
  // The publishers are advertised in the constructor's body, before the controller can report.
  BaseEvents events;
  events.on_wheel_frame = [this](const WheelFrameSent& sent) {
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
  };
  events.on_battery = [this](uint8_t percent, core::Clock::time_point arrival) {
    if (!ros_layer::wanted(battery_pub_)) return;
    battery_pub_.publish(toBatteryState(batteryReading(percent), arrival_stamps_(arrival)));
  };
  events.on_odometry = [this](const OdometrySample& sample) { publishOdometry(sample); };
  events.on_cmd_vel_timeout = [this] {
    ROS_INFO_THROTTLE(10.0, "no cmd_vel for %.2f s (base/cmd_vel_timeout): commanding zero speed",
                      tuned()->controller.cmd_vel_timeout);
  };
  events.on_silent = [this](double seconds) {
    ROS_ERROR_THROTTLE(10.0,
                       "no reply from the base on %s for %.1f s (battery requests unanswered)",
                       link_.options().path.c_str(), seconds);
  };
  events.on_timeout_error = [] {
    ROS_WARN_THROTTLE(5.0, "base reported a connection-timeout error (FF): sending Reset");
  };
  events.on_heading_source = [this](kinematics::HeadingSource source) {
    if (source == kinematics::HeadingSource::kImu) {
      ROS_INFO("odom heading: following the IMU's yaw (base/use_imu_heading)");
    } else if (source == kinematics::HeadingSource::kImuStale) {
      ROS_WARN(
          "odom heading: no IMU yaw for %.2f s (is the body's telemetry flowing?); integrating "
          "the commanded turn from the last fused heading until it returns",
          std::chrono::duration<double>(kinematics::kImuHeadingStaleAfter).count());
    }
  };
  events.on_unknown_reply = [](const Frame& frame) {
    ROS_DEBUG_THROTTLE(5.0, "base sent a frame with unknown MSGID 0x%02X", frame.msg_id);
  };
  return events;
}

BaseRos::BaseRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params,
                 core::SerialLink& link)
    : link_(link),
      replaying_(!params.replay_bag.empty()),
      loop_rate_(params.loop_rate),
      arrival_stamps_(params),
      params_(params.section(kBaseSection)),
      tuned_(std::make_shared<const BaseParams>(params.section(kBaseSection))),
      tf_pub_(params.section(kBaseSection).publish_tf ? advertiseTf() : ::ros::Publisher()),
      odom_pub_(nh.advertise<nav_msgs::Odometry>("odom", 50)),
      controller_(makeBaseConfig(params), link.writer(), events()) {
  wheel_command_pub_ = nh.advertise<serial_robot_driver::WheelCommand>("wheel_command", 50);
  battery_pub_ = nh.advertise<sensor_msgs::BatteryState>("battery", params.publisherQueue(5));
  wheel_states_pub_ = nh.advertise<sensor_msgs::JointState>("wheel_states", 50);

  link.addListener(&controller_);

  // tcpNoDelay: a cmd_vel must not sit in Nagle's buffer; the loop puts it on the wire at once.
  cmd_vel_sub_ = ros_layer::subscribeGuarded(nh, inputRefusals(), "cmd_vel", 10, &BaseRos::onCmdVel,
                                             this, ::ros::TransportHints().tcpNoDelay());
  reset_srv_ =
      ros_layer::advertiseGuarded(nh, inputRefusals(), "base/reset", &BaseRos::onReset, this);
  reset_odometry_srv_ = ros_layer::advertiseGuarded(nh, inputRefusals(), "base/reset_odometry",
                                                    &BaseRos::onResetOdometry, this);
  clear_encoders_srv_ = ros_layer::advertiseGuarded(nh, inputRefusals(), "base/clear_encoders",
                                                    &BaseRos::onClearEncoders, this);
}

void BaseRos::onCmdVel(const geometry_msgs::Twist::ConstPtr& msg) {
  // Accepted now: noted before the e-stop check, so an e-stop from here on voids it.
  const BaseController::Generation accepted = controller_.generation();
  // Counted with the other refused commands; the controller ignores it (and counts it) itself.
  if (e_stop_) e_stop_->refuse("cmd_vel");
  switch (controller_.submitCommand(msg->linear.x, msg->angular.z, accepted)) {
    case CommandOutcome::kNotFinite:
      inputRefusals().refused("cmd_vel");
      ROS_WARN_THROTTLE(
          1.0, "cmd_vel rejected: linear.x=%f angular.z=%f is not finite; commanding zero speed",
          msg->linear.x, msg->angular.z);
      break;
    case CommandOutcome::kVoided:
      ROS_WARN_THROTTLE(1.0, "cmd_vel ignored: e-stop engaged after this command was accepted");
      break;
    case CommandOutcome::kStored:
    case CommandOutcome::kEStopEngaged:
      break;
  }
}

void BaseRos::attachEStop(core::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) { controller_.setEStop(engaged); });
}

void BaseRos::publishOdometry(const OdometrySample& sample) {
  // Called on the control loop's thread once per tick; never touches the port. What nobody
  // subscribes to is not built (/tf included: it goes out whenever anyone listens to /tf).
  const ::ros::Time stamp = ::ros::Time::now();
  // ~base/publish_tf switched on at runtime: /tf is advertised from then on.
  if (tuned()->publish_tf && !tf_pub_) tf_pub_ = advertiseTf();
  const bool odom_wanted = ros_layer::wanted(odom_pub_);
  const bool tf_wanted = tuned()->publish_tf && ros_layer::wanted(tf_pub_);
  std::optional<nav_msgs::Odometry> odom;
  if (odom_wanted || tf_wanted) {
    odom = toOdometry(sample, {params_.odom_frame, params_.base_frame}, stamp);
  }
  if (odom_wanted) odom_pub_.publish(*odom);
  if (ros_layer::wanted(wheel_states_pub_)) publishWheelStates(sample, stamp);
  if (tf_wanted) publishTf(*odom, sample);
}

void BaseRos::publishTf(const nav_msgs::Odometry& odom, const OdometrySample& sample) {
  tf2_msgs::TFMessage tf;
  tf.transforms.resize(1);
  geometry_msgs::TransformStamped& transform = tf.transforms[0];
  transform.header = odom.header;
  transform.child_frame_id = odom.child_frame_id;
  transform.transform.translation.x = sample.pose.x;
  transform.transform.translation.y = sample.pose.y;
  transform.transform.rotation = odom.pose.pose.orientation;
  tf_pub_.publish(tf);
}

::ros::Publisher BaseRos::advertiseTf() {
  // As tf2_ros::TransformBroadcaster advertises it, with a publisher whose subscribers we can
  // count.
  return ::ros::NodeHandle().advertise<tf2_msgs::TFMessage>("/tf", 100);
}

void BaseRos::publishWheelStates(const OdometrySample& sample, const ::ros::Time& stamp) {
  // The wheels' angles as robot_state_publisher wants them: the same accepted motion as odom.
  wheel_states_pub_.publish(toWheelStates(sample, params_.base_frame, params_.left_wheel_joint,
                                          params_.right_wheel_joint, stamp));
}

void BaseRos::retune(const ros_layer::DriverParams& params) {
  controller_.retune(makeBaseConfig(params));
  std::atomic_store(&tuned_, std::make_shared<const BaseParams>(params.section(kBaseSection)));
}

bool BaseRos::onResetOdometry(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  controller_.resetOdometry();
  res.success = true;
  res.message = "odometry pose reset to zero";
  return true;
}

bool BaseRos::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = controller_.sendReset();
  res.message =
      res.success ? "Reset sent" : "base port " + link_.options().path + " is not connected";
  return true;
}

bool BaseRos::onClearEncoders(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = controller_.sendClearEncoders();
  // The AP1 reports no encoder counts, so clearing them changes nothing the node publishes.
  res.message = res.success ? "clear-encoders sent (the node never reads encoder counts; odom is "
                              "not affected: use base/reset_odometry)"
                            : "base port " + link_.options().path + " is not connected";
  return true;
}

core::StatusReport BaseRos::status() {
  const std::shared_ptr<const BaseParams> limits = tuned();
  return baseStatus(controller_.stats(), {link_.options().path, link_.connected()},
                    {limits->battery_warn_percent, limits->battery_error_percent});
}

void BaseRos::useCapabilities(const core::Capabilities& capabilities) {
  // Connected whenever a heading is measured: ~base/use_imu_heading can be switched on at runtime.
  core::HeadingSource* heading = capabilities.find<core::HeadingSource>();
  if (!heading) return;
  heading->addHeadingListener([this](double yaw, core::Clock::time_point arrival) {
    // A replay's arrival times are the recording's; the base loop runs on this machine's clock.
    controller_.onImuYaw(yaw, replaying_ ? core::Clock::now() : arrival);
  });
}

std::string BaseRos::startupSummary() const {
  std::ostringstream text;
  text << "loop " << loop_rate_ << " Hz, battery poll " << params_.controller.battery_poll_rate
       << " Hz";
  return text.str();
}

}  // namespace serial_robot_driver::devices::base::ros
