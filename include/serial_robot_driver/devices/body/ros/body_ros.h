// ROS front end of the servo controller board (devices::body::BodyDevice): joint_states, imu/data,
// foot_pressure and telemetry out (published on the link's reader thread as each frame is decoded,
// stamped with the frame's arrival time); joint_commands in; imu/calibrate (it waits
// ~imu/calibration_time, so it runs on a queue and spinner thread of its own, never holding up the
// reader or the global queue).
#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include <memory>

#include "serial_robot_driver/devices/body/body_device.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/device_front_end.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/publish_wanted.h"
#include "serial_robot_driver/ros/queue_spinner.h"
#include "serial_robot_driver/ros/reused_message.h"

namespace serial_robot_driver::devices::body::ros {

class BodyRos : public ros_layer::DeviceFrontEnd {
 public:
  /// Advertises the topics and imu/calibrate and adds its outputs to `device` (before it starts).
  /// `device` must outlive this object.
  BodyRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, BodyDevice& device);
  ~BodyRos() override;

  /// Starts imu/calibrate's spinner.
  void start() override;
  /// Stops taking joint commands and calibrations.
  void shutdown() override;

 private:
  void publishFrame(const BodyFrame& frame);
  /// joint_states_.next() filled from `readings`.
  void fillJointStateMessage(const JointReadings& readings, const ::ros::Time& stamp);

  BodyDevice& device_;
  const ros_layer::ArrivalStamps arrival_stamps_;
  ros_layer::CountedPublisher joint_states_pub_;
  ros_layer::CountedPublisher imu_pub_;
  ros_layer::CountedPublisher foot_pressure_pub_;
  ros_layer::CountedPublisher telemetry_pub_;
  // Reader thread only: the messages of the last frame, filled again when nobody else holds them.
  ros_layer::ReusedMessage<sensor_msgs::JointState> joint_states_;
  ros_layer::ReusedMessage<sensor_msgs::Imu> imu_;
  uint64_t joint_state_names_ = 0;  ///< the names_generation joint_states_ holds
  ::ros::Subscriber joint_commands_sub_;
  // imu/calibrate: its own queue and one thread, as a call blocks for ~imu/calibration_time.
  ::ros::CallbackQueue calibration_queue_;
  ::ros::NodeHandle calibration_nh_;  // the node's namespace, bound to calibration_queue_
  ::ros::ServiceServer calibrate_srv_;
  std::unique_ptr<ros_layer::QueueSpinner> calibration_spinner_;
  bool shut_down_ = false;
};

}  // namespace serial_robot_driver::devices::body::ros
