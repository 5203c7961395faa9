// ROS face of the UART bus servos: the servo/* services, servo_states / servo_commands and the
// "servo_bus" diagnostic status. The bus itself (transactions, validation, messages, the move
// queue and the poll schedule) is device::ServoBus; this class only translates.
//
// Threading model (the threads start in start()):
//  - The services are served from OWN callback queues (ServoBusServices), never the global one: a
//    servo call blocks for up to timeout * (retries + 1), a scan or a reset for many of those, a
//    call with `wait` for a whole motion, and on the global queue that would hold up cmd_vel and
//    joint_commands.
//  - The stop services (servo/spin, servo/relax, servo/damping, servo/hold) have a queue
//    (StopCallQueue) and a thread of their own, so they never wait behind a long call on the
//    other queue. Their bus turns are urgent work (BusPriority::kStop): after the one transaction
//    attempt in flight, before every waiting call, queued move and poll; a holder that keeps the
//    bus across several transactions (servo/write, servo/reset_user_data) hands it over before
//    its next attempt. Their calls are short (a frame, or one transaction, per servo); the long
//    one, a servo/spin with wait, gives way to a stop call queued behind it (and any call waiting
//    for a motion's completion gives way to a stop waiting for the bus).
//  - Every other service is served from the second queue by two threads: one call waits on the
//    bus while another is accepted and queued behind the bus lock.
//  - servo_commands arrive on the caller's (global) queue: the callback only checks the message
//    and queues the moves in device::ServoBus, whose worker thread writes them and runs the
//    servo_states poll (servo_states is published from that thread); both take the bus after any
//    waiting service call, so a service call waits for one transaction at most.
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoHold.h"
#include "serial_robot_driver/ServoInfo.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_services.h"
#include "serial_robot_driver/devices/servo_bus/ros/trajectory_bus_joints.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_diagnostics.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_status.h"
#include "serial_robot_driver/devices/servo_bus/servo_joint_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::devices::servo_bus::ros {

/// The bus device's configuration: what the parameters bound into ServoBusParams::bus, plus the
/// polled servos (state_ids and the joint_ids servos).
ServoBusConfig makeServoBusConfig(const ros_layer::DriverParams& params);

// Joint names and servo_commands' checks are the core's (device/servo_joint_commands.h).
using servo_bus::ServoCommandBatch;
using servo_bus::servoIdFromJointName;
using servo_bus::servoJointName;
using servo_bus::servoStatusMessage;  // the core's (servo_services.h)
/// servo_bus::toServoMoves of the message's names, positions (rad) and velocities (rad/s).
ServoCommandBatch toServoMoves(const sensor_msgs::JointState& msg, uint16_t interval_ms);

class ServoBusRos : public ros_layer::DeviceInterface {
 public:
  /// Registers the client with `link` and advertises servo/* in `nh`'s namespace. Must be
  /// constructed before the link is started.
  ServoBusRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, core::SerialLink& link);
  ~ServoBusRos();
  ServoBusRos(const ServoBusRos&) = delete;
  ServoBusRos& operator=(const ServoBusRos&) = delete;

  /// Starts the service threads (the stop thread first) and the bus's worker: calls are served
  /// from here on.
  void start() override;
  /// Fails a call in progress, stops the services and joins the spinner threads. Idempotent.
  void shutdown() override;
  core::StatusReport status() override { return diagnostics_.busStatus(commands_rejected_.load()); }
  /// "servo_bus servo <id>", one status per polled servo, also while ~servo_bus/health_rate is 0
  /// (it may be tuned on): its readings against its own limits (an offline servo is an ERROR),
  /// its identity, a WARN for each setting that does not fit.
  std::vector<NamedStatus> extraStatuses() override;
  /// The ~servo_bus tunables: timeout and retries from the next transaction, state_rate from the
  /// next poll, command_interval_ms from the next servo_commands message.
  void retune(const ros_layer::DriverParams& params) override;
  /// ~servo_bus/joint_ids as trajectory joints: one queued move per segment.
  std::vector<ros_layer::TrajectoryJoints> trajectoryJoints() override;
  /// The servos set moving (ServoBus::motionInForce()).
  std::string motionInForce() const override { return bus_.motionInForce(); }
  void attachTrajectories(trajectory::TrajectoryExecutor& executor) override {
    claims_.attachTrajectories(executor);
  }
  /// Engaged: queued moves dropped, a SPIN stop to every servo the driver set moving; motion
  /// services and servo_commands refused until it is released (reads, pings, scans still work).
  void attachEStop(core::EStop& e_stop) override;

 private:
  ServoBusEvents makeEvents();
  void onServoCommands(const sensor_msgs::JointState::ConstPtr& msg);

  // Bus servos as joints (trajectories): fixed before the bus starts, read on the worker thread.
  const std::vector<trajectory::BusJoint> bus_joints_;
  const double state_rate_;

  core::SerialLink& link_;
  ServoBus bus_;
  ServoMotionClaims claims_;   // the e-stop and the trajectories, over bus_joints_
  ServoBusServices services_;  // servo/*, on queues and threads of their own
  bool started_ = false;
  bool shut_down_ = false;

  // servo_states / servo_commands
  ::ros::NodeHandle topics_nh_;  // the caller's namespace on the caller's queue
  ::ros::Publisher states_pub_;
  ::ros::Subscriber commands_sub_;
  std::atomic<uint16_t> command_interval_ms_;  // retune() from the dynamic_reconfigure callback
  std::atomic<uint64_t> commands_rejected_{0};

  // servo_states asked vs achieved, between two diagnostics updates (the diagnostics thread only).
  ServoBusDiagnostics diagnostics_;
};

}  // namespace serial_robot_driver::devices::servo_bus::ros
