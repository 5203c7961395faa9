// ROS front end of the UART bus servos (devices::servo_bus::ServoBusDevice): the servo/* services,
// servo_states out and servo_commands in. The bus itself (transactions, validation, messages, the
// move queue and the poll schedule) is the device's; this class only translates.
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
//  - servo_commands arrive on the caller's (global) queue: the device checks the message and
//    queues the moves in its ServoBus, whose worker thread writes them and runs the servo_states
//    poll (servo_states is published from that thread); both take the bus after any waiting
//    service call, so a service call waits for one transaction at most.
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
#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_services.h"
#include "serial_robot_driver/devices/servo_bus/ros/trajectory_bus_joints.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_device.h"
#include "serial_robot_driver/ros/device_front_end.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/publish_wanted.h"

namespace serial_robot_driver::devices::servo_bus::ros {

// Joint names, servo_commands' checks and the calls' messages are the core's.
using servo_bus::ServoCommandBatch;
using servo_bus::servoIdFromJointName;
using servo_bus::servoJointName;
using servo_bus::servoStatusMessage;

class ServoBusRos : public ros_layer::DeviceFrontEnd {
 public:
  /// Advertises servo/*, servo_states and servo_commands in `nh`'s namespace and adds its
  /// outputs to `device` (before it starts). `device` must outlive this object.
  ServoBusRos(::ros::NodeHandle& nh, ServoBusDevice& device);
  ~ServoBusRos() override;
  ServoBusRos(const ServoBusRos&) = delete;
  ServoBusRos& operator=(const ServoBusRos&) = delete;

  /// Starts the service threads (the stop thread first): calls are served from here on.
  void start() override;
  /// Stops taking servo_commands, stops the services and joins their threads (after the device
  /// failed a call waiting on the bus). Idempotent.
  void shutdown() override;

 private:
  ServoBusDevice& device_;
  ServoBusServices services_;  // servo/*, on queues and threads of their own
  bool started_ = false;
  bool shut_down_ = false;
  ros_layer::CountedPublisher states_pub_;
  ::ros::Subscriber commands_sub_;
};

}  // namespace serial_robot_driver::devices::servo_bus::ros
