// ROS face of the servo controller board: joint_states, imu/data, foot_pressure and telemetry out
// (published on the link's reader thread as each frame is decoded, stamped with the frame's
// arrival time); joint_commands in (one sync-write frame per message); imu/calibrate (the gyro
// bias, device::GyroBiasCalibrator: it waits ~imu/calibration_time, so it runs on a queue and
// spinner thread of its own, never holding up the reader or the global queue); one diagnostic
// status.
#pragma once

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_srvs/Trigger.h>

#include <memory>

#include "serial_robot_driver/core/event_rate.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/body/body_readings.h"
#include "serial_robot_driver/devices/body/body_status.h"
#include "serial_robot_driver/devices/body/gyro_bias.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/queue_spinner.h"

namespace serial_robot_driver::devices::body::ros {

class BodyRos : public ros_layer::DeviceInterface {
 public:
  /// Registers the controller on `link` (before the link starts) and advertises the topics.
  /// `link` must outlive this object.
  BodyRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, core::SerialLink& link);
  ~BodyRos() override;

  /// Starts imu/calibrate's spinner; the rest speaks when the link's reader hands it a frame.
  void start() override;
  /// Stops taking joint commands and calibrations (one under way is refused). Frames that still
  /// arrive before the link stops are published.
  void shutdown() override;
  /// The telemetry rate, the frames' counters and the gyro calibration (logs telemetry stopping
  /// and resuming).
  core::StatusReport status() override;
  /// The ~imu tunables (accel_scale, gyro_scale, angle_scale) from the next telemetry frame on.
  void retune(const ros_layer::DriverParams& params) override;

  const BodyController& controller() const { return controller_; }
  /// Offers the IMU's yaw (imuYaw()) as a HeadingSource: its listeners are called on the reader
  /// thread with every frame's yaw and arrival time (~base/use_imu_heading: the base's odometry).
  void offerCapabilities(core::Capabilities& capabilities) override {
    capabilities.offer<core::HeadingSource>(imu_heading_);
  }
  /// The body's joints, streamed: one sync-write frame per loop tick.
  std::vector<ros_layer::TrajectoryJoints> trajectoryJoints() override;
  void attachTrajectories(trajectory::TrajectoryExecutor& executor) override {
    trajectory_ = &executor;
  }
  /// joint_commands are refused while it holds.
  /// Engaged: the controller's motion gate is locked, so no sync-write goes out from then on,
  /// even one already waiting; joint_commands are refused and counted.
  void attachEStop(core::EStop& e_stop) override;
  /// The gyro is calibrated only while nothing moves the robot (the node's MotionQuery) nor the
  /// e-stop is engaged.
  void useCapabilities(const core::Capabilities& capabilities) override {
    motion_query_ = capabilities.find<core::MotionQuery>();
  }
  /// A joint command written lately (BodyController::motionInForce); trajectories answer for
  /// themselves (the node asks its trajectory server).
  std::string motionInForce() const override {
    return controller_.motionInForce(core::Clock::now());
  }

 private:
  void publishTelemetry(const Telemetry& telemetry, core::Clock::time_point arrival);
  void onJointCommand(const sensor_msgs::JointState::ConstPtr& msg);
  bool onCalibrate(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  /// Why the robot is not held still now, "" when it is (reader and calibration threads).
  std::string notStill() const;

  core::SerialLink& link_;
  const ros_layer::ArrivalStamps arrival_stamps_;
  /// Swapped whole by retune() (~imu scales) and loaded once per frame by the reader thread, so
  /// a frame is converted with one set of scales (std::atomic_load / atomic_store).
  std::shared_ptr<const ImuParams> imu_params_;
  // Set before the links start, read on the reader and calibration threads.
  const core::MotionQuery* motion_query_ = nullptr;
  core::EStop* e_stop_ = nullptr;       // the node's, set before start()
  GyroBiasCalibrator gyro_calibrator_;  // before controller_: telemetry feeds it
  BodyController controller_;
  core::EventRate telemetry_rate_;  // ticked on the reader thread (locks)
  JointReadings joint_readings_;    // reader thread only: each frame's, reused

  ::ros::Publisher joint_states_pub_;
  ::ros::Publisher imu_pub_;
  ::ros::Publisher foot_pressure_pub_;
  ::ros::Publisher telemetry_pub_;
  ::ros::Subscriber joint_commands_sub_;
  core::HeadingFeed imu_heading_;  // listeners added before the link starts
  // The node's trajectory executor (its own threading comment); set before the link starts.
  trajectory::TrajectoryExecutor* trajectory_ = nullptr;
  BodyStatus status_;  // diagnostics timer thread only
  // imu/calibrate: its own queue and one thread, as a call blocks for ~imu/calibration_time.
  ::ros::CallbackQueue calibration_queue_;
  ::ros::NodeHandle calibration_nh_;  // the node's namespace, bound to calibration_queue_
  ::ros::ServiceServer calibrate_srv_;
  std::unique_ptr<ros_layer::QueueSpinner> calibration_spinner_;
  bool shut_down_ = false;
};

}  // namespace serial_robot_driver::devices::body::ros
