#include "serial_robot_driver/ros/base_interface.h"

#include <sensor_msgs/BatteryState.h>

#include "serial_robot_driver/WheelCommand.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

device::BaseConfig makeBaseConfig(const DriverParams& params) {
  device::BaseConfig config;
  config.geometry.wheel_diameter = params.base.wheel_diameter;
  config.geometry.wheel_separation = params.base.wheel_separation;
  config.geometry.encoder_resolution = params.base.encoder_resolution;
  config.geometry.pid_rate = params.base.pid_rate;
  config.max_wheel_speed = params.base.max_wheel_speed;
  config.max_wheel_accel = params.base.max_wheel_accel;
  config.cmd_vel_timeout = params.base.cmd_vel_timeout;
  config.speed_dithering = params.base.speed_dithering;
  config.battery_poll_rate = params.base.battery_poll_rate;
  config.loop_rate = params.loop_rate;
  return config;
}

device::BaseEvents BaseInterface::events() {
  // The publishers are advertised in the constructor's body, before the controller can report.
  device::BaseEvents events;
  events.on_wheel_frame = [this](const device::WheelFrameSent& sent) {
    if (wheel_command_pub_.getNumSubscribers() == 0) return;  // 50 Hz: skip work nobody reads
    serial_robot_driver::WheelCommand msg;
    msg.header.stamp = ros::Time::now();
    msg.left_ticks = sent.ticks.left;
    msg.right_ticks = sent.ticks.right;
    msg.seq = sent.seq;
    msg.reset_before = sent.reset_before;
    msg.left_speed = sent.speeds.x();
    msg.right_speed = sent.speeds.y();
    wheel_command_pub_.publish(msg);
  };
  events.on_battery = [this](uint8_t percent, device::Clock::time_point arrival) {
    sensor_msgs::BatteryState msg;
    msg.header.stamp = arrival_stamps_(arrival);
    // The base reports only a percentage; everything else is unknown (NaN per the message docs).
    const float unknown = std::numeric_limits<float>::quiet_NaN();
    msg.voltage = msg.temperature = msg.current = unknown;
    msg.charge = msg.capacity = msg.design_capacity = unknown;
    msg.percentage = percent / 100.0f;
    msg.power_supply_status = sensor_msgs::BatteryState::POWER_SUPPLY_STATUS_UNKNOWN;
    msg.power_supply_health = sensor_msgs::BatteryState::POWER_SUPPLY_HEALTH_UNKNOWN;
    msg.power_supply_technology = sensor_msgs::BatteryState::POWER_SUPPLY_TECHNOLOGY_UNKNOWN;
    msg.present = true;
    battery_pub_.publish(msg);
  };
  events.on_timeout_error = [] {
    ROS_WARN_THROTTLE(5.0, "base reported a connection-timeout error (FF): sending Reset");
  };
  events.on_unknown_reply = [](const protocol::base::Frame& frame) {
    ROS_DEBUG_THROTTLE(5.0, "base sent a frame with unknown MSGID 0x%02X", frame.msg_id);
  };
  return events;
}

BaseInterface::BaseInterface(ros::NodeHandle& nh, const DriverParams& params,
                             device::SerialLink& link, diagnostic_updater::Updater& diagnostics)
    : link_(link),
      arrival_stamps_(params),
      controller_(makeBaseConfig(params), link.writer(), events()) {
  wheel_command_pub_ = nh.advertise<serial_robot_driver::WheelCommand>("wheel_command", 50);
  battery_pub_ = nh.advertise<sensor_msgs::BatteryState>("battery", params.publisherQueue(5));

  link.addListener(&controller_);

  // tcpNoDelay: a cmd_vel must not sit in Nagle's buffer; the loop puts it on the wire at once.
  cmd_vel_sub_ = nh.subscribe("cmd_vel", 10, &BaseInterface::onCmdVel, this,
                              ros::TransportHints().tcpNoDelay());
  reset_srv_ = nh.advertiseService("base/reset", &BaseInterface::onReset, this);
  clear_encoders_srv_ = nh.advertiseService("base/clear_encoders", &BaseInterface::onClearEncoders, this);
  diagnostics.add("base", this, &BaseInterface::diagnose);
}

void BaseInterface::onCmdVel(const geometry_msgs::Twist::ConstPtr& msg) {
  if (!controller_.setCommand(msg->linear.x, msg->angular.z)) {
    ROS_WARN_THROTTLE(1.0, "cmd_vel rejected: linear.x=%f angular.z=%f is not finite; commanding zero speed",
                      msg->linear.x, msg->angular.z);
  }
}

bool BaseInterface::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = controller_.sendReset();
  res.message = res.success ? "Reset sent" : "base port " + link_.options().path + " is not connected";
  return true;
}

bool BaseInterface::onClearEncoders(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  res.success = controller_.sendClearEncoders();
  res.message = res.success ? "clear-encoders sent"
                            : "base port " + link_.options().path + " is not connected";
  return true;
}

void BaseInterface::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const device::BaseStats s = controller_.stats();
  const bool connected = link_.connected();
  if (!connected) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "port " + link_.options().path + " not connected");
  } else if (s.timeout_errors_received > 0 && s.resets_sent == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "base in timeout error");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "driving");
  }
  status.hardware_id = link_.options().path;
  status.add("port", link_.options().path);
  status.add("connected", connected);
  status.add("speed frames out", s.speed_frames);
  status.add("immediate frames (new cmd_vel)", s.immediate_frames);
  status.add("resets sent", s.resets_sent);
  status.add("FF timeout errors received", s.timeout_errors_received);
  status.add("battery requests", s.battery_requests);
  status.add("battery replies", s.battery_replies);
  status.add("unknown replies", s.unknown_replies);
  status.add("bad replies", s.bad_replies);
  status.add("write failures", s.write_failures);
  status.add("cmd_vel timeouts", s.cmd_vel_timeouts);
  status.add("rejected cmd_vel (NaN/Inf)", s.rejected_commands);
  status.add("loop overruns", s.loop_overruns);
  status.addf("last loop period (ms)", "%.3f", s.last_period_ms);
  status.addf("worst loop period (ms)", "%.3f", s.worst_period_ms);
  if (s.battery_percent) status.add("battery (%)", static_cast<int>(*s.battery_percent));
}

}  // namespace serial_robot_driver::ros_layer
