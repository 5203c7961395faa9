// ROS face of the AP1 base: cmd_vel in (and the node's e-stop); wheel_command, odom (+ tf),
// wheel_states, battery and diagnostics out; base/reset, base/clear_encoders and
// base/reset_odometry services. The control loop itself is device::BaseController's thread; odom
// and tf are published from it, once per tick. odom is the motion the base was commanded and
// accepted, not a measurement: the AP1 reports no encoder counts.
#pragma once

#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <memory>

#include "serial_robot_driver/devices/base/base_controller.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::devices::base::ros {

class BaseRos : public ros_layer::DeviceInterface {
 public:
  /// Registers the controller on `link` (before the link starts) and advertises the topics and
  /// services. `link` must outlive this object.
  BaseRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, core::SerialLink& link);
  /// Starts the control loop (after the links are started).
  void start() override { controller_.start(); }
  /// Stops the loop and writes a zero-speed frame (before the port closes).
  void shutdown() override { controller_.stop(); }
  core::StatusReport status() override;
  /// The ~base tunables: the controller's from its next tick on, and the interface's own.
  void retune(const ros_layer::DriverParams& params) override;
  /// Engaged: zero speed held at once (frames keep flowing as the heartbeat), cmd_vel ignored.
  void attachEStop(core::EStop& e_stop) override;
  /// ~base/use_imu_heading: the heading another device measures (a HeadingSource, the IMU's yaw)
  /// goes to the controller, which only stores it (kinematics::HeadingFusion).
  void useCapabilities(const core::Capabilities& capabilities) override;
  /// The loop and battery poll rates.
  std::string startupSummary() const override;
  /// A cmd_vel in force or wheels still ramping down.
  std::string motionInForce() const override { return controller_.motionInForce(); }

 private:
  BaseEvents events();
  void onCmdVel(const geometry_msgs::Twist::ConstPtr& msg);
  void publishOdometry(const OdometrySample& sample);
  /// odom's pose as odom -> base_link on /tf.
  void publishTf(const nav_msgs::Odometry& odom, const OdometrySample& sample);
  static ::ros::Publisher advertiseTf();
  void publishWheelStates(const OdometrySample& sample, const ::ros::Time& stamp);
  bool onResetOdometry(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onReset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onClearEncoders(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);

  core::SerialLink& link_;
  const bool replaying_;    // ~replay_bag: headings arrive stamped with the recording's clock
  const double loop_rate_;  // Hz, as started
  ros_layer::ArrivalStamps arrival_stamps_;  // before controller_: its events use it
  const BaseParams params_;  // as started: frames and joint names (the tunables: tuned())
  /// ~base as last tuned, swapped whole by retune() (read on the loop and diagnostics threads).
  std::shared_ptr<const BaseParams> tuned() const { return std::atomic_load(&tuned_); }
  std::shared_ptr<const BaseParams> tuned_;
  // Before the controller: its loop publishes through them until it stops.
  ::ros::Publisher tf_pub_;  // /tf; advertised by the loop thread when first needed
  ::ros::Publisher odom_pub_;
  ::ros::Publisher wheel_states_pub_;  // advertised in the constructor's body
  BaseController controller_;
  ::ros::Publisher wheel_command_pub_;
  ::ros::Publisher battery_pub_;
  ::ros::Subscriber cmd_vel_sub_;
  core::EStop* e_stop_ = nullptr;  // the node's, set before start()
  ::ros::ServiceServer reset_odometry_srv_;
  ::ros::ServiceServer reset_srv_;
  ::ros::ServiceServer clear_encoders_srv_;
};

}  // namespace serial_robot_driver::devices::base::ros
