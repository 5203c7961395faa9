// The servo controller board as a device of the driver, whole and ROS-free: the controller on its
// port, the gyro bias calibration, the IMU's heading it offers, its joints for trajectories, what
// the e-stop means for it, its status and its ~imu tunables. Front ends attach to it: they call
// its inputs with core values and register outputs that receive each telemetry frame's readings.
//
// Threading: the outputs are called on the port's reader thread as each frame is decoded;
// commandJoints() on its caller's thread; calibrateGyro() blocks its caller (a thread of its own
// in the front end) for ~imu/calibration_time.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/event_rate.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/outcome.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/core/swapped_value.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/body/body_readings.h"
#include "serial_robot_driver/devices/body/body_status.h"
#include "serial_robot_driver/devices/body/gyro_bias.h"

namespace serial_robot_driver::devices::body {

/// A joint command (joint_commands): positions (rad) of the named joints.
struct JointCommand {
  std::vector<std::string> names;
  std::vector<double> positions;
};

/// One telemetry frame as the device read it, valid during the call.
struct BodyFrame {
  const Telemetry& telemetry;       ///< the frame in raw units
  core::Clock::time_point arrival;  ///< when its last byte was read
  const JointReadings& joints;      ///< positions (rad) and velocities (rad/s)
  const ImuParams& imu;             ///< the ~imu values in force for this frame
  GyroVector gyro_bias;             ///< raw LSB (sensor axes) to subtract from the frame's gyro
  const Eigen::Matrix3d& imu_axes;  ///< axisMapMatrix(imu.axis_map), for imuReading()
};

/// The ~imu values in force, with what each frame's conversion derives from them worked out once
/// per set of values (at start and on each retune) instead of once per frame and consumer.
struct ImuInForce {
  explicit ImuInForce(const ImuParams& tuned)
      : params(tuned), axes(axisMapMatrix(tuned.axis_map)), gyro_units(gyroUnits(tuned)) {}
  ImuParams params;
  Eigen::Matrix3d axes;  ///< the axis map's matrix
  GyroUnits gyro_units;
};

/// What a front end receives; every listener may be empty.
struct BodyOutputs {
  std::function<void(const BodyFrame&)> frame;
};

class BodyDevice : public core::Device {
 public:
  /// Registers the controller on `link` (before the link starts). `link` must outlive this.
  BodyDevice(const params::DriverParams& params, core::SerialLink& link);
  ~BodyDevice() override;

  /// Before start(): `outputs` receives the readings from then on, beside the others added.
  void addOutputs(BodyOutputs outputs) { outputs_.push_back(std::move(outputs)); }

  /// joint_commands: one sync-write frame. Refused (the reason returned, "" when obeyed, counted
  /// and logged): the e-stop engaged, an unknown joint, a position that is not finite, ... A
  /// joint under a trajectory is taken over by it, and its goal aborted.
  std::string commandJoints(const JointCommand& command);
  /// imu/calibrate: averages the gyro for ~imu/calibration_time while the robot is held still.
  core::Outcome calibrateGyro();

  void start() override {}
  /// Stops taking joint commands and calibrations (one under way is refused). Frames that still
  /// arrive before the link stops are reported.
  void shutdown() override;
  /// The telemetry rate, the frames' counters and the gyro calibration (logs telemetry stopping
  /// and resuming).
  core::StatusReport status() override;
  /// The ~imu tunables (accel_scale, gyro_scale, angle_scale, ...) from the next frame on.
  void retune(const ImuParams& tuned);
  void retune(const params::DriverParams& in_force) override;

  /// Offers the IMU's yaw as a HeadingSource: its listeners are called on the reader thread with
  /// every frame's yaw and arrival time (~base/use_imu_heading: the base's odometry).
  void offerCapabilities(core::Capabilities& capabilities) override {
    capabilities.offer<core::HeadingSource>(imu_heading_);
  }
  /// The gyro is calibrated only while nothing moves the robot (the MotionQuery) nor the e-stop
  /// is engaged.
  void useCapabilities(const core::Capabilities& capabilities) override {
    motion_query_ = capabilities.find<core::MotionQuery>();
  }
  /// The body's joints, streamed: one sync-write frame per loop tick.
  std::vector<trajectory::TrajectoryJoints> trajectoryJoints() override;
  void attachTrajectories(trajectory::TrajectoryExecutor& executor) override;
  /// Engaged: the controller's motion gate is locked, so no sync-write goes out from then on,
  /// even one already waiting; joint commands are refused and counted.
  void attachEStop(core::EStop& e_stop) override;
  /// A joint command written lately (BodyController::motionInForce); trajectories answer for
  /// themselves.
  std::string motionInForce() const override {
    return controller_.motionInForce(core::Clock::now());
  }
  bool inMotion() const override { return controller_.inMotion(core::Clock::now()); }

  const BodyController& controller() const { return controller_; }

 private:
  void onTelemetry(const Telemetry& telemetry, core::Clock::time_point arrival);
  /// Why the robot is not held still now, "" when it is (reader and calibration threads).
  std::string notStill() const;
  /// notStill() as a bool that builds no text: asked once per frame.
  bool moving() const;
  void logFlow(BodyStatus::FlowChange flow) const;

  core::SerialLink& link_;
  /// Swapped whole by retune(), so a frame is converted with one set of scales; frame_imu_ is
  /// the reader thread's (onTelemetry's), read once per frame.
  core::SwappedValue<ImuInForce> imu_;
  core::SwappedValue<ImuInForce>::Reader frame_imu_;
  std::vector<BodyOutputs> outputs_;  // added before start(), then only read
  // Set before the links start, read on the reader and calibration threads.
  const core::MotionQuery* motion_query_ = nullptr;
  core::EStop* e_stop_ = nullptr;
  /// Its yaw's variance is ~imu/orientation_variance; listeners added before the link starts.
  core::HeadingFeed imu_heading_;
  // The trajectory executor (its own threading comment); set before the link starts.
  trajectory::TrajectoryExecutor* trajectory_ = nullptr;
  std::vector<std::size_t> trajectory_tracks_;  // each joint's track in it, looked up once
  core::LogThrottle refused_log_{1.0};
  core::LogThrottle command_log_{1.0};
  GyroBiasCalibrator gyro_calibrator_;  // before controller_: telemetry feeds it
  core::EventRate telemetry_rate_;      // ticked on the reader thread (locks)
  JointConversion joint_conversion_;    // of controller_'s joints, made before the link starts
  JointReadings joint_readings_;        // reader thread only: each frame's, reused
  BodyStatus status_;                   // diagnostics thread only
  BodyController controller_;           // last: its frames use the members above
};

}  // namespace serial_robot_driver::devices::body
