// driver_node: one node that owns the robot's serial port(s).
//
// The devices it drives are the registered ones (core/device_module.h), built and owned by
// core::DriverCore; each has a ROS front end of its own (devices/<name>/ros/<name>_ros.h) with its
// topics and services, listed in full in docs/node_api.md:
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
//    in main, or the nodelet manager's threads), and write their frame from there at once (the
//    base under its loop's lock, BaseController::submitCommand); servo/* services have their own queue and
//    spinner because they wait on the bus;
//  - diagnostics are published from a steady timer on the global queue, every ~diagnostic_period.
//  - the dynamic_reconfigure servers (~base, ~imu, ~servo_bus, ~trajectory; ros/runtime_tuning.h)
//    answer on the global queue too; a change reaches each device under the device's own lock
//    (the base loop's mutex, the IMU scales swapped whole, the bus client's state lock, the
//    trajectory server's mutex), from its next tick, frame or transaction on.
//  - trajectory goals, cancels, joint_trajectory and the trajectory timer (one sync-write per loop
//    tick) run on the global queue too (ros/trajectory_server.h).
//  - with ~realtime_priority the reader threads and the base loop run SCHED_FIFO at it, the node's
//    other threads (roscpp's, the spinners) one below, where the process may (core/realtime.h);
//    the core logs once what applies.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_msgs/Bool.h>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/ros/device_front_end.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::dds_front {
class Ros2Graph;
}  // namespace serial_robot_driver::dds_front

namespace serial_robot_driver::ros_layer {

class RuntimeTuning;
class TrajectoryServer;
class WireCapture;

class DriverNode {
 public:
  /// `stream_factory` builds each port's stream (default: a termios serial port); benchmarks pass
  /// their own, e.g. a stream that polls.
  DriverNode(ros::NodeHandle nh, ros::NodeHandle private_nh, DriverParams params,
             core::SerialLink::StreamFactory stream_factory = {});
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
  /// Each device's ROS front end (its RosDeviceModule), attached before the core starts.
  void attachFrontEnds();
  /// follow_joint_trajectory / joint_trajectory when a device offers joints.
  void serveTrajectories();
  /// Subscribes e_stop.
  void connectEStop();
  /// The core's statuses (ports, devices and their own, the e-stop) on the diagnostics updater.
  void addStatuses();
  void onEStop(const std_msgs::Bool::ConstPtr& msg);

  ros::NodeHandle nh_;
  DriverParams params_;
  ros::Subscriber e_stop_sub_;
  diagnostic_updater::Updater diagnostics_;
  std::unique_ptr<WireCapture> capture_;  // ~capture; outlives the ports that report to it
  std::atomic<bool> shut_down_{false};
  /// The ports, the devices, their wiring and their order.
  std::unique_ptr<core::DriverCore> core_;
  /// The devices' topics and services, in the devices' order; destroyed before core_'s devices.
  std::vector<std::unique_ptr<DeviceFrontEnd>> front_ends_;
  /// ~ros2/enabled: the DDS front end on the same devices (nothing otherwise).
  std::unique_ptr<dds_front::Ros2Graph> ros2_;
  /// follow_joint_trajectory / joint_trajectory for the core's trajectories; null without joints.
  std::unique_ptr<TrajectoryServer> trajectory_;
  double diagnostics_period_ = 1.0;  ///< s; the updater's ~diagnostic_period at start-up
  ros::SteadyTimer diagnostics_timer_;
  /// The dynamic_reconfigure servers (~base, ~imu, ...); declared after core_ and trajectory_,
  /// destroyed first.
  std::unique_ptr<RuntimeTuning> tuning_;
};

}  // namespace serial_robot_driver::ros_layer
