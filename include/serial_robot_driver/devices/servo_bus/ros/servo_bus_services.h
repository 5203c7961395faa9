// The servo/* services of the bus servos: each one copies its request into a call of the core's
// ServoServices (servo_services.h: the call, its outcome, log lines and refusals) and the reply
// into its response, never throws through (guarded) and always returns the message; served from
// queues of their own (the threading model: servo_bus_ros.h): the stop services (servo/spin,
// servo/relax, servo/damping, servo/hold) from the stop queue, whose bus turns are urgent work,
// every other from the second one.
#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <memory>
#include <vector>

#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/devices/servo_bus/ros/stop_call_queue.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"
#include "serial_robot_driver/devices/servo_bus/servo_services.h"
#include "serial_robot_driver/ros/queue_spinner.h"

namespace serial_robot_driver::devices::servo_bus::ros {

class ServoBusServices {
 public:
  /// Advertises servo/* in `nh`'s namespace, served once start() runs. `bus`, `claims` and
  /// `refusals` (where refused requests are counted) must outlive this object.
  ServoBusServices(::ros::NodeHandle& nh, ServoBus& bus, ServoMotionClaims& claims,
                   core::InputRefusals& refusals);
  ~ServoBusServices();
  ServoBusServices(const ServoBusServices&) = delete;
  ServoBusServices& operator=(const ServoBusServices&) = delete;

  /// Starts the service threads, the stop thread first.
  void start();
  /// Stops the services and joins their threads (after the bus failed a call waiting on it).
  /// Idempotent.
  void shutdown();

 private:
  /// servo/ping, read, read_angle, scan, read_all, info: allowed while the e-stop holds.
  void advertiseReads();
  /// servo/write and servo/reset_user_data: they change a servo's settings (logged at INFO).
  void advertiseWrites();
  /// servo/move and servo/rotate: motion, claimed (the e-stop, the trajectories).
  void advertiseMoves();
  /// servo/spin, damping, relax, hold, on the stop queue.
  void advertiseStops();

  ServoBusClient& client_;  // the bus's: told of the stop calls queued
  core::InputRefusals& refusals_;
  ServoServices handlers_;
  ::ros::CallbackQueue queue_;
  ::ros::NodeHandle nh_;  // the caller's namespace, bound to queue_
  StopCallQueue stop_queue_;
  ::ros::NodeHandle stop_nh_;  // the caller's namespace, bound to stop_queue_
  std::vector<::ros::ServiceServer> services_;
  std::unique_ptr<ros_layer::QueueSpinner> spinner_;
  std::unique_ptr<ros_layer::QueueSpinner> stop_spinner_;
  bool shut_down_ = false;
};

}  // namespace serial_robot_driver::devices::servo_bus::ros
