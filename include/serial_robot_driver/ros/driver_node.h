// driver_node: one node that owns the robot's serial port(s).
//
// The devices it drives are the registered ones (device/device_module.h); each has a ROS interface
// of its own (ros/*_interface.h) with its topics and services, listed in full in docs/node_api.md:
//   base      in cmd_vel; out odom (+ tf), wheel_command, battery;
//             base/reset, base/reset_odometry, base/clear_encoders
//   body      in joint_commands; out joint_states, imu/data, foot_pressure, telemetry
//   servo_bus in servo_commands; out servo_states; servo/ping, read, write, read_angle, move,
//             scan, rotate, spin, damping, relax, hold, read_all, reset_user_data
// and the node itself: e_stop (one device::EStop handed to every device and the trajectories),
// /diagnostics (one status per port and per device), serial_raw (with
// ~capture), the follow_joint_trajectory action and joint_trajectory topic for the joints of every
// device (ros/trajectory_server.h). Parameters: see ros/driver_params.h and config/robot.yaml.
//
// Threading model:
//  - one reader thread per port (device::SerialLink) decodes and publishes telemetry and base
//  replies
//    as soon as their last byte is read;
//  - the base control loop runs on its own thread (device::BaseController);
//  - cmd_vel, joint_commands and base/* services run on the global callback queue (a QueueSpinner
//    in main, or the nodelet manager's threads); servo/* services have their own queue and
//    spinner because they wait on the bus;
//  - diagnostics are published from a steady timer on the global queue, every ~diagnostic_period.
//  - the dynamic_reconfigure servers (~base, ~imu, ~servo_bus, ~trajectory; ros/runtime_tuning.h)
//    answer on the global queue too; a change reaches each device under the device's own lock
//    (the base loop's mutex, the IMU scales swapped whole, the bus client's state lock, the
//    trajectory server's mutex), from its next tick, frame or transaction on.
//  - trajectory goals, cancels, joint_trajectory and the trajectory timer (one sync-write per loop
//    tick) run on the global queue too (ros/trajectory_server.h).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_msgs/Bool.h>

#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/device/capabilities.h"
#include "serial_robot_driver/device/device_module.h"
#include "serial_robot_driver/device/e_stop.h"
#include "serial_robot_driver/device/input_refusals.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/trajectory/executor.h"

namespace serial_robot_driver::ros_layer {

class DeviceInterface;
class RuntimeTuning;
class PortMonitor;
class TrajectoryServer;
class WireCapture;

class DriverNode {
 public:
  /// `stream_factory` builds each port's stream (default: a termios serial port); benchmarks pass
  /// their own, e.g. a stream that polls.
  DriverNode(ros::NodeHandle nh, ros::NodeHandle private_nh, DriverParams params,
             device::SerialLink::StreamFactory stream_factory = {});
  ~DriverNode();

  /// Opens the ports (in the background: a missing port is waited for), then starts the devices
  /// (the base loop, the servo service spinner).
  void start();
  /// Publishes every diagnostic status now (a replay's last counters before the node exits).
  void updateDiagnostics() { diagnostics_.force_update(); }
  /// Shuts the devices down in order (the base first, writing a zero-speed frame), then stops the
  /// ports. Idempotent.
  void shutdown();

 private:
  struct Port {
    std::unique_ptr<device::SerialLink> link;
    std::unique_ptr<PortMonitor> monitor;
  };
  /// One SerialLink per path the enabled devices name, with its monitor and status.
  void openPorts(const device::SerialLink::StreamFactory& stream_factory);
  /// The options of the port at `path` shared by `users`.
  device::SerialLinkOptions linkOptions(
      const std::string& path, const std::vector<const device::DeviceModule*>& users) const;
  device::SerialLink& portFor(const std::string& path);
  /// The ROS side of every enabled device on its port, with its statuses.
  void makeDevices();
  /// One trajectory executor (and its ROS server) over every device's joints, attached to them.
  void connectTrajectories();
  /// Cross-device wiring by kind (device/capabilities.h): every device's offers, then its asks;
  /// the node offers the MotionQuery over every device and the trajectories.
  void connectCapabilities();
  /// One line for the log: ports, the devices on each, rates.
  std::string startupSummary() const;
  void diagnosePort(const Port& port, diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Hands the e-stop to the trajectories and the devices and subscribes e_stop.
  void connectEStop();
  void onEStop(const std_msgs::Bool::ConstPtr& msg);
  void diagnoseEStop(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_;
  DriverParams params_;
  /// The one e-stop of every actuator; outlives the devices and the trajectory server.
  device::EStop e_stop_;
  device::InputRefusals input_refusals_;  // the node's own topic's (e_stop)
  ros::Subscriber e_stop_sub_;
  diagnostic_updater::Updater diagnostics_;
  std::unique_ptr<WireCapture> capture_;  // ~capture; outlives the ports that report to it
  std::map<std::string, Port> ports_;
  /// The trajectories over every device's joints; null when none has any. Outlives the devices,
  /// which hold a reference to it, and its server.
  std::unique_ptr<trajectory::TrajectoryExecutor> trajectory_executor_;
  /// follow_joint_trajectory / joint_trajectory for trajectory_executor_.
  std::unique_ptr<TrajectoryServer> trajectory_;
  /// The MotionQuery the devices were offered (connectCapabilities); outlives them.
  std::unique_ptr<device::MotionQuery> motion_query_;
  /// In start and shutdown order: the registered devices' order (cmake/devices.cmake).
  std::vector<std::unique_ptr<DeviceInterface>> devices_;
  std::vector<std::string> device_names_;  ///< devices_' registered names
  double diagnostics_period_ = 1.0;  ///< s; the updater's ~diagnostic_period at start-up
  ros::SteadyTimer diagnostics_timer_;
  /// The dynamic_reconfigure servers (~base, ~imu, ...); declared after devices_ and
  /// trajectory_, destroyed first.
  std::unique_ptr<RuntimeTuning> tuning_;
  std::atomic<bool> shut_down_{false};  // read by the ports' monitors on the reader threads
};

}  // namespace serial_robot_driver::ros_layer
