#include "serial_robot_driver/devices/body/ros/body_ros.h"

#include <sensor_msgs/Imu.h>

#include <boost/make_shared.hpp>

#include "serial_robot_driver/FootPressure.h"
#include "serial_robot_driver/Telemetry.h"
#include "serial_robot_driver/devices/body/body_trajectory_joints.h"
#include "serial_robot_driver/devices/body/ros/body_conversions.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/publish_wanted.h"

namespace serial_robot_driver::devices::body::ros {

using body::gyroUnits;

BodyRos::BodyRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params,
                 core::SerialLink& link)
    : link_(link),
      arrival_stamps_(params),
      imu_params_(std::make_shared<const ImuParams>(params.section(kImuSection))),
      gyro_calibrator_([this] { return notStill(); }),
      controller_(makeBodyJoints(params.section(kBodySection)), link.writer(),
                  {[this](const Telemetry& telemetry, core::Clock::time_point arrival) {
                    publishTelemetry(telemetry, arrival);
                  }}),
      // Expected telemetry rates; measured on ROS time, as diagnostic_updater's FrequencyStatus.
      telemetry_rate_(1.0, 1000.0, [] { return ::ros::Time::now().toSec(); }),
      calibration_nh_(nh) {
  // Queues hold a few frames: a slow subscriber should drop old frames, not delay new ones.
  joint_states_pub_ =
      nh.advertise<sensor_msgs::JointState>("joint_states", params.publisherQueue(20));
  imu_pub_ = nh.advertise<sensor_msgs::Imu>("imu/data", params.publisherQueue(20));
  foot_pressure_pub_ =
      nh.advertise<serial_robot_driver::FootPressure>("foot_pressure", params.publisherQueue(20));
  telemetry_pub_ =
      nh.advertise<serial_robot_driver::Telemetry>("telemetry", params.publisherQueue(20));
  // tcpNoDelay: a joint command must not wait in Nagle's buffer.
  joint_commands_sub_ = ros_layer::subscribeGuarded(nh, inputRefusals(), "joint_commands", 10,
                                                    &BodyRos::onJointCommand, this,
                                                    ::ros::TransportHints().tcpNoDelay());
  link.addListener(&controller_);
  calibration_nh_.setCallbackQueue(&calibration_queue_);
  calibrate_srv_ = ros_layer::advertiseGuarded(calibration_nh_, inputRefusals(), "imu/calibrate",
                                               &BodyRos::onCalibrate, this);
  if (params.section(kImuSection).calibrate_on_start) {
    gyro_calibrator_.calibrateOnStart([](const GyroCalibrationOutcome& outcome) {
      if (outcome.success) {
        ROS_INFO("imu/calibrate_on_start: %s", outcome.message.c_str());
      } else {
        ROS_WARN("imu/calibrate_on_start: %s", outcome.message.c_str());
      }
    });
  }
}

void BodyRos::start() {
  if (calibration_spinner_ || shut_down_) return;
  calibration_spinner_ = std::make_unique<ros_layer::QueueSpinner>(&calibration_queue_, 1);
  calibration_spinner_->start();
}

std::string BodyRos::notStill() const {
  if (e_stop_ && e_stop_->engaged()) return "the e-stop is engaged";
  return motion_query_ ? motion_query_->motionInForce() : std::string();
}

bool BodyRos::onCalibrate(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  // On calibration_queue_'s own thread: blocking here for the averaging holds up nothing else.
  const std::shared_ptr<const ImuParams> imu = std::atomic_load(&imu_params_);
  const GyroCalibrationOutcome outcome =
      gyro_calibrator_.calibrate(imu->calibration_time, gyroUnits(*imu), "imu/calibrate");
  res.success = outcome.success;
  res.message = outcome.message;
  if (outcome.success) {
    ROS_INFO("%s", outcome.message.c_str());
  } else {
    ROS_WARN("%s", outcome.message.c_str());
  }
  return true;
}

void BodyRos::retune(const ros_layer::DriverParams& params) {
  std::atomic_store(&imu_params_, std::make_shared<const ImuParams>(params.section(kImuSection)));
}

void BodyRos::shutdown() {
  joint_commands_sub_.shutdown();
  controller_.gate().close();  // no position goes out once the node is shutting down
  if (shut_down_) return;
  shut_down_ = true;
  gyro_calibrator_.cancel();  // a call waiting for its averaging returns now
  calibrate_srv_.shutdown();
  if (calibration_spinner_) calibration_spinner_->stop();
}

BodyRos::~BodyRos() { shutdown(); }

void BodyRos::attachEStop(core::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) { controller_.gate().setLocked(engaged); });
}

std::vector<ros_layer::TrajectoryJoints> BodyRos::trajectoryJoints() {
  return {bodyTrajectoryJoints(controller_)};
}

void BodyRos::publishTelemetry(const Telemetry& telemetry, core::Clock::time_point arrival) {
  // Runs on the link's reader thread; ros::Publisher::publish is thread-safe. A message nobody
  // subscribes to is not even built: at hundreds of frames per second that is most of the CPU.
  telemetry_rate_.tick();
  const ::ros::Time stamp = arrival_stamps_(arrival);
  const auto& joints = controller_.joints();
  // Converted once per frame for every consumer, into vectors that keep their capacity. The
  // trajectories need every frame: their goals are checked against it.
  updateJointReadings(telemetry, joints, &joint_readings_);
  if (trajectory_) {
    trajectory_->updateActual(joint_readings_.names, joint_readings_.positions,
                              joint_readings_.velocities);
  }
  // joint_states and imu/data go out as shared pointers: a subscriber in the same nodelet manager
  // gets this very message, not a serialized copy (so each is a message of its own).
  if (ros_layer::wanted(joint_states_pub_)) {
    joint_states_pub_.publish(
        boost::make_shared<sensor_msgs::JointState>(toJointState(joint_readings_, stamp)));
  }
  const std::shared_ptr<const ImuParams> imu = std::atomic_load(&imu_params_);
  if (imu_heading_.wanted()) imu_heading_.publish(imuYaw(telemetry, *imu), arrival);
  // Every frame feeds the calibration, subscribers or not (calibrate_on_start, imu/calibrate).
  const GyroVector gyro_bias = gyro_calibrator_.onSample(
      {static_cast<double>(telemetry.imu[kGyroX]), static_cast<double>(telemetry.imu[kGyroY]),
       static_cast<double>(telemetry.imu[kGyroZ])},
      arrival, gyroUnits(*imu), imu->calibration_time);
  if (ros_layer::wanted(imu_pub_)) {
    imu_pub_.publish(
        boost::make_shared<sensor_msgs::Imu>(toImu(telemetry, *imu, stamp, gyro_bias)));
  }
  if (ros_layer::wanted(foot_pressure_pub_)) {
    if (auto foot = toFootPressure(telemetry, stamp)) foot_pressure_pub_.publish(*foot);
  }
  if (ros_layer::wanted(telemetry_pub_)) {
    telemetry_pub_.publish(toTelemetryMsg(telemetry, joints, stamp));
  }
}

void BodyRos::onJointCommand(const sensor_msgs::JointState::ConstPtr& msg) {
  // Accepted now: noted before the e-stop check, so an e-stop from here on voids it.
  const core::MotionGate::Generation accepted = controller_.gate().generation();
  if (e_stop_ && e_stop_->refuse("joint_commands")) {
    ROS_WARN_THROTTLE(1.0, "joint_commands refused: e_stop is engaged");
    return;
  }
  const ros_layer::JointCommand command = ros_layer::fromJointState(*msg);
  JointCommandResult result;
  const auto send = [&] {
    result = controller_.sendJointCommand(command.names, command.positions, accepted);
    return result.ok();
  };
  // A joint under a trajectory is taken over by this command, and its goal aborted.
  if (trajectory_) {
    trajectory_->takeOver(command.names, "joint_commands", send);
  } else {
    send();
  }
  if (!result.ok()) inputRefusals().refused("joint_commands");
  if (!result.ok() || !result.out_of_range.empty()) {
    ROS_WARN_THROTTLE(1.0, "joint_commands: %s", result.message().c_str());
  }
}

core::StatusReport BodyRos::status() {
  // As diagnostic_updater starts every status: it stands while the rate's window has no length.
  core::StatusReport report;
  report.summary(core::StatusLevel::kError, "No message was set");
  telemetry_rate_.addTo(report);  // OK / WARN from the telemetry rate, plus its own keys
  BodyStatus::Update update = status_.update(controller_.stats(), link_.stats().framer,
                                             {link_.options().path, link_.connected()});
  gyro_calibrator_.report(update.report, gyroUnits(*std::atomic_load(&imu_params_)));
  // Once per outage, not once per period.
  if (update.flow == BodyStatus::FlowChange::kStopped) {
    ROS_WARN(
        "body on %s: telemetry stopped (no frame since the last diagnostics period); is the "
        "board powered and streaming?",
        link_.options().path.c_str());
  } else if (update.flow == BodyStatus::FlowChange::kResumed) {
    ROS_INFO("body on %s: telemetry resumed", link_.options().path.c_str());
  }
  report.mergeSummary(update.report.level, update.report.message);
  if (!update.report.hardware_id.empty()) report.hardware_id = update.report.hardware_id;
  for (auto& value : update.report.values) report.values.push_back(std::move(value));
  return report;
}

}  // namespace serial_robot_driver::devices::body::ros
