// ROS face of the UART bus servos: the servo/* services and the "servo_bus"
// diagnostic status. The bus logic (transactions, validation, messages) is device::ServoBusClient.
//
// Threading: the services are served from this class's OWN callback queue by its own QueueSpinner
// (2 threads). A servo call blocks for up to timeout * (retries + 1), or for a whole motion when
// `wait` is set; on the global queue that would hold up cmd_vel and joint_commands.
// servo_commands arrive on the caller's (global) queue: the callback only checks the message and
// queues the moves. One worker thread of this class writes the queued moves and runs the
// servo_states poll; both take the bus after any waiting service call (the poll as background
// work), so a service call waits for one transaction at most.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/device/servo_bus_client.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/queue_spinner.h"
#include "serial_robot_driver/ros/trajectory_bus_joints.h"

namespace serial_robot_driver::ros_layer {

/// Client options from ~servo_bus/{timeout, retries, allow_dangerous_writes}.
device::ServoBusOptions makeServoBusOptions(const DriverParams& params);

/// The bus servo id of a servo_states / servo_commands joint name ("servo_<id>", id 0..254), or
/// -1 when the name is not of that form.
int servoIdFromJointName(const std::string& name);
std::string servoJointName(uint8_t id);

/// The moves of one servo_commands message, or the reason it is rejected (nothing is sent then).
/// Positions in rad, velocities in rad/s (an entry without a velocity, or 0: ROTATE with
/// `interval_ms`; else CMD 12 by velocity).
struct ServoCommandBatch {
  std::vector<device::MoveRequest> moves;
  std::string error;  ///< non-empty: rejected
};
ServoCommandBatch toServoMoves(const sensor_msgs::JointState& msg, uint16_t interval_ms);

class ServoBusInterface : public DeviceInterface {
 public:
  /// Registers the client with `link` and advertises servo/* in `nh`'s namespace. Must be
  /// constructed before the link is started.
  ServoBusInterface(ros::NodeHandle& nh, const DriverParams& params, device::SerialLink& link,
                    diagnostic_updater::Updater& diagnostics);
  ~ServoBusInterface();
  ServoBusInterface(const ServoBusInterface&) = delete;
  ServoBusInterface& operator=(const ServoBusInterface&) = delete;

  /// Starts the service spinner: calls are served from here on.
  void start() override;
  /// Fails a call in progress, stops the services and joins the spinner threads. Idempotent.
  void shutdown() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;
  /// ~servo_bus/joint_ids as trajectory joints: one queued move per segment.
  std::vector<TrajectoryJoints> trajectoryJoints() override;
  void attachTrajectories(TrajectoryServer* server) override { trajectory_ = server; }

 private:
  /// One servo of ~servo_bus/state_ids and its poll schedule.
  struct PolledServo {
    uint8_t id = 0;
    device::Clock::time_point next_poll;
    std::chrono::milliseconds backoff{0};  ///< 0: online
    uint64_t failures = 0;
  };

  void onServoCommands(const sensor_msgs::JointState::ConstPtr& msg);
  /// Queues a move for the worker; the latest target of a servo replaces a queued one.
  /// worker_mutex_ held.
  void queueMoveLocked(const device::MoveRequest& move);
  /// A motion service (`source`) for servo `id`: when it is a joint under a trajectory, the
  /// trajectory stops (its goal aborts) and its queued move is dropped.
  void yieldJoint(uint8_t id, const char* source);
  void workerLoop();
  void pollOnce(PolledServo& servo);

  device::SerialLink& link_;
  device::ServoBusClient client_;
  diagnostic_updater::Updater& diagnostics_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;  // the caller's namespace, bound to queue_
  std::vector<ros::ServiceServer> services_;
  std::unique_ptr<QueueSpinner> spinner_;
  bool shut_down_ = false;

  // servo_states / servo_commands
  ros::NodeHandle topics_nh_;  // the caller's namespace on the caller's queue
  ros::Publisher states_pub_;
  ros::Subscriber commands_sub_;
  const std::chrono::duration<double> poll_period_;
  const uint16_t command_interval_ms_;
  std::thread worker_;
  std::mutex worker_mutex_;  // guards the fields below
  std::condition_variable worker_cv_;
  bool worker_stop_ = false;
  std::deque<device::MoveRequest> queued_moves_;
  std::vector<PolledServo> polled_;
  uint64_t states_published_ = 0;
  uint64_t commands_sent_ = 0;
  uint64_t commands_rejected_ = 0;
  uint64_t command_failures_ = 0;

  // Bus servos as joints (trajectories); set before start().
  std::vector<trajectory::BusJoint> bus_joints_;
  double state_rate_ = 10.0;
  TrajectoryServer* trajectory_ = nullptr;
};

}  // namespace serial_robot_driver::ros_layer
