#include "serial_robot_driver/devices/body/ros/body_ros.h"

#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>

#include "serial_robot_driver/FootPressure.h"
#include "serial_robot_driver/Telemetry.h"
#include "serial_robot_driver/devices/body/ros/body_conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/publish_wanted.h"
#include "serial_robot_driver/ros/trigger_service.h"

namespace serial_robot_driver::devices::body::ros {

BodyRos::BodyRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params, BodyDevice& device)
    : device_(device), arrival_stamps_(params), calibration_nh_(nh) {
  // Queues hold a few frames: a slow subscriber should drop old frames, not delay new ones.
  joint_states_pub_ = ros_layer::advertiseCounted<sensor_msgs::JointState>(
      nh, "joint_states", params.publisherQueue(20));
  imu_pub_ =
      ros_layer::advertiseCounted<sensor_msgs::Imu>(nh, "imu/data", params.publisherQueue(20));
  foot_pressure_pub_ = ros_layer::advertiseCounted<serial_robot_driver::FootPressure>(
      nh, "foot_pressure", params.publisherQueue(20));
  telemetry_pub_ = ros_layer::advertiseCounted<serial_robot_driver::Telemetry>(
      nh, "telemetry", params.publisherQueue(20));
  device.addOutputs({[this](const BodyFrame& frame) { publishFrame(frame); }});

  core::InputRefusals& refusals = device.inputRefusals();
  // tcpNoDelay: a joint command must not wait in Nagle's buffer.
  const ros_layer::SubscriberCallback<sensor_msgs::JointState> on_command =
      [this](const sensor_msgs::JointState::ConstPtr& msg) {
        device_.commandJoints(fromJointState(*msg));
      };
  joint_commands_sub_ = nh.subscribe<sensor_msgs::JointState>(
      "joint_commands", 10, ros_layer::guardedSubscriber(refusals, "joint_commands", on_command),
      ::ros::VoidConstPtr(), ::ros::TransportHints().tcpNoDelay());
  calibration_nh_.setCallbackQueue(&calibration_queue_);
  calibrate_srv_ = ros_layer::advertiseTrigger(calibration_nh_, refusals, "imu/calibrate",
                                               [&device] { return device.calibrateGyro(); });
}

BodyRos::~BodyRos() { shutdown(); }

void BodyRos::start() {
  if (calibration_spinner_ || shut_down_) return;
  calibration_spinner_ = std::make_unique<ros_layer::QueueSpinner>(&calibration_queue_, 1);
  calibration_spinner_->start();
}

void BodyRos::shutdown() {
  joint_commands_sub_.shutdown();
  if (shut_down_) return;
  shut_down_ = true;
  calibrate_srv_.shutdown();
  if (calibration_spinner_) calibration_spinner_->stop();
}

void BodyRos::publishFrame(const BodyFrame& frame) {
  // Runs on the link's reader thread; ros::Publisher::publish is thread-safe. A message nobody
  // subscribes to is not even built: at hundreds of frames per second that is most of the CPU.
  const ::ros::Time stamp = arrival_stamps_(frame.arrival);
  // joint_states and imu/data go out as shared pointers: a subscriber in the same nodelet manager
  // gets this very message, not a serialized copy (so a message is reused only once it is ours).
  // Both are built before the first goes out: roscpp's sending thread, woken by the first, then
  // finds the second queued too instead of being woken once more.
  const bool joint_states_wanted = ros_layer::wanted(joint_states_pub_);
  const bool imu_wanted = ros_layer::wanted(imu_pub_);
  if (joint_states_wanted) fillJointStateMessage(frame.joints, stamp);
  if (imu_wanted) {
    const ImuReading reading =
        imuReading(frame.telemetry, frame.imu, frame.imu_axes, frame.gyro_bias);
    fillImu(reading, frame.imu, stamp, &imu_.next());
  }
  if (joint_states_wanted) joint_states_pub_.publish(joint_states_.get());
  if (imu_wanted) imu_pub_.publish(imu_.get());
  if (ros_layer::wanted(foot_pressure_pub_)) {
    if (auto foot = toFootPressure(frame.telemetry, stamp)) foot_pressure_pub_.publish(*foot);
  }
  if (ros_layer::wanted(telemetry_pub_)) {
    telemetry_pub_.publish(toTelemetryMsg(frame.telemetry, device_.controller().joints(), stamp));
  }
}

void BodyRos::fillJointStateMessage(const JointReadings& readings, const ::ros::Time& stamp) {
  sensor_msgs::JointState& msg = joint_states_.next();
  // The names are copied only into a new message or when they changed: twenty string copies a
  // frame were about a tenth of the reader's instructions.
  if (joint_states_.renewed() || joint_state_names_ != readings.names_generation) {
    msg.name = readings.names;
    joint_state_names_ = readings.names_generation;
  }
  fillJointStateValues(readings, stamp, &msg);
}

}  // namespace serial_robot_driver::devices::body::ros
