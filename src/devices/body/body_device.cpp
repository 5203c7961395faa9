#include "serial_robot_driver/devices/body/body_device.h"

#include "serial_robot_driver/devices/body/body_trajectory_joints.h"

namespace serial_robot_driver::devices::body {

using core::log;
using core::LogLevel;

namespace {

void logOutcome(const GyroCalibrationOutcome& outcome, const char* prefix) {
  log(outcome.success ? LogLevel::kInfo : LogLevel::kWarn, "%s%s", prefix, outcome.message.c_str());
}

}  // namespace

BodyDevice::BodyDevice(const params::DriverParams& params, core::SerialLink& link)
    : link_(link),
      imu_(std::make_shared<const ImuInForce>(params.section(kImuSection))),
      frame_imu_(imu_),
      imu_heading_(params.section(kImuSection).orientation_variance),
      gyro_calibrator_([this] { return notStill(); }, {}, [this] { return moving(); }),
      // Expected telemetry rates, as diagnostic_updater's FrequencyStatus.
      telemetry_rate_(
          1.0, 1000.0,
          [] {
            return std::chrono::duration<double>(core::Clock::now().time_since_epoch()).count();
          }),
      controller_(makeBodyJoints(params.section(kBodySection)), link.writer(),
                  {[this](const Telemetry& telemetry, core::Clock::time_point arrival) {
                    onTelemetry(telemetry, arrival);
                  }}) {
  joint_conversion_ = makeJointConversion(controller_.joints());
  link.addListener(&controller_);
  if (params.section(kImuSection).calibrate_on_start) {
    gyro_calibrator_.calibrateOnStart([](const GyroCalibrationOutcome& outcome) {
      logOutcome(outcome, "imu/calibrate_on_start: ");
    });
  }
}

BodyDevice::~BodyDevice() { shutdown(); }

std::string BodyDevice::notStill() const {
  if (e_stop_ && e_stop_->engaged()) return "the e-stop is engaged";
  return motion_query_ ? motion_query_->motionInForce() : std::string();
}

bool BodyDevice::moving() const {
  return (e_stop_ && e_stop_->engaged()) || (motion_query_ && motion_query_->inMotion());
}

void BodyDevice::onTelemetry(const Telemetry& telemetry, core::Clock::time_point arrival) {
  // On the link's reader thread. What subscribers receive goes out first; what only this node
  // uses follows (the trajectories' measured positions, the odometry's heading, the gyro
  // calibration's stillness check, which asks every device), so none of it delays joint_states.
  telemetry_rate_.tick();
  // Converted once per frame for every consumer, into vectors that keep their capacity.
  updateJointReadings(telemetry, joint_conversion_, &joint_readings_);
  const JointReadings& joints = joint_readings_;
  const ImuInForce& imu = frame_imu_.current();
  const BodyFrame frame{telemetry, arrival, joints, imu.params, gyro_calibrator_.bias(), imu.axes};
  for (const BodyOutputs& outputs : outputs_) {
    if (outputs.frame) outputs.frame(frame);
  }
  // The trajectories need every frame: their goals are checked against it.
  if (trajectory_) {
    trajectory_->updateActual(trajectory_tracks_, joints.positions, joints.velocities);
  }
  if (imu_heading_.wanted()) {
    imu_heading_.publish(imuYaw(telemetry, imu.params, imu.axes), arrival);
  }
  // Every frame feeds the calibration (calibrate_on_start, imu/calibrate). A bias it finds applies
  // from the next frame on.
  gyro_calibrator_.onSample(
      {static_cast<double>(telemetry.imu[kGyroX]), static_cast<double>(telemetry.imu[kGyroY]),
       static_cast<double>(telemetry.imu[kGyroZ])},
      arrival, imu.gyro_units, imu.params.calibration_time);
}

std::string BodyDevice::commandJoints(const JointCommand& command) {
  // Accepted now: noted before the e-stop check, so an e-stop from here on voids it.
  const core::MotionGate::Generation accepted = controller_.gate().generation();
  if (e_stop_ && e_stop_->refuse("joint_commands")) {
    if (refused_log_.pass()) log(LogLevel::kWarn, "joint_commands refused: e_stop is engaged");
    return "joint_commands refused: e_stop is engaged";
  }
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
  if ((!result.ok() || !result.out_of_range.empty()) && command_log_.pass()) {
    log(LogLevel::kWarn, "joint_commands: %s", result.message().c_str());
  }
  return result.ok() ? std::string() : "joint_commands: " + result.message();
}

core::Outcome BodyDevice::calibrateGyro() {
  const std::shared_ptr<const ImuInForce> imu = imu_.get();
  const GyroCalibrationOutcome outcome =
      gyro_calibrator_.calibrate(imu->params.calibration_time, imu->gyro_units, "imu/calibrate");
  logOutcome(outcome, "");
  return {outcome.success, outcome.message};
}

void BodyDevice::retune(const ImuParams& tuned) {
  imu_.set(std::make_shared<const ImuInForce>(tuned));
}

void BodyDevice::retune(const params::DriverParams& in_force) {
  retune(in_force.section(kImuSection));
}

void BodyDevice::shutdown() {
  controller_.gate().close();  // no position goes out once the driver is shutting down
  gyro_calibrator_.cancel();   // a call waiting for its averaging returns now
}

void BodyDevice::attachEStop(core::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) { controller_.gate().setLocked(engaged); });
}

void BodyDevice::attachTrajectories(trajectory::TrajectoryExecutor& executor) {
  // The joints never change: each frame's readings (in joint order) go to these tracks.
  std::vector<std::string> names;
  for (const BodyJoint& joint : controller_.joints()) names.push_back(joint.name);
  trajectory_tracks_ = executor.tracksOf(names);
  trajectory_ = &executor;
}

std::vector<trajectory::TrajectoryJoints> BodyDevice::trajectoryJoints() {
  return {bodyTrajectoryJoints(controller_)};
}

core::StatusReport BodyDevice::status() {
  // As diagnostic_updater starts every status: it stands while the rate's window has no length.
  core::StatusReport report;
  report.summary(core::StatusLevel::kError, "No message was set");
  telemetry_rate_.addTo(report);  // OK / WARN from the telemetry rate, plus its own keys
  BodyStatus::Update update = status_.update(controller_.stats(), link_.stats().framer,
                                             {link_.options().path, link_.connected()});
  gyro_calibrator_.report(update.report, imu_.get()->gyro_units);
  logFlow(update.flow);
  report.mergeSummary(update.report.level, update.report.message);
  if (!update.report.hardware_id.empty()) report.hardware_id = update.report.hardware_id;
  for (auto& value : update.report.values) report.values.push_back(std::move(value));
  return report;
}

void BodyDevice::logFlow(BodyStatus::FlowChange flow) const {
  // Once per outage, not once per period.
  const char* path = link_.options().path.c_str();
  if (flow == BodyStatus::FlowChange::kStopped) {
    log(LogLevel::kWarn,
        "body on %s: telemetry stopped (no frame since the last diagnostics period); is the "
        "board powered and streaming?",
        path);
  } else if (flow == BodyStatus::FlowChange::kResumed) {
    log(LogLevel::kInfo, "body on %s: telemetry resumed", path);
  }
}

}  // namespace serial_robot_driver::devices::body
