// The AP1 base as a device of the driver, whole and ROS-free: it owns the controller on its port,
// its status, its tunables, what the e-stop and the IMU's heading mean for it. Front ends (ROS,
// DDS, ...) attach to it: they call its inputs with core values and register outputs that receive
// its readings. Every check of an input, its counting and its log line are here, once.
//
// Threading: the inputs run on their caller's thread (any); the outputs are called on the
// controller's loop thread (wheel frames, odometry) and the port's reader thread (battery),
// without the controller's lock held, in the order they were added.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/outcome.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/base/base_controller.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/base/base_readings.h"

namespace serial_robot_driver::devices::base {

/// A velocity command (cmd_vel): forward speed (m/s) and turn rate (rad/s, counter-clockwise).
struct TwistCommand {
  double linear_x = 0.0;
  double angular_z = 0.0;
};

/// What a front end receives; every listener may be empty.
struct BaseOutputs {
  /// Each wheel frame written (the loop's, an immediate one, the last words).
  std::function<void(const WheelFrameSent&)> wheel_frame;
  /// After every scheduled tick: the odometry and the wheels' angles.
  std::function<void(const OdometrySample&)> odometry;
  /// Each battery reply; `arrival` is when its last byte was read.
  std::function<void(const BatteryReading&, core::Clock::time_point arrival)> battery;
};

class BaseDevice : public core::Device {
 public:
  /// Registers the controller on `link` (before the link starts). `link` must outlive this;
  /// `clock` empty: the steady clock.
  BaseDevice(const params::DriverParams& params, core::SerialLink& link,
             std::shared_ptr<core::LoopClock> clock = {});

  /// Before start(): `outputs` receives the readings from then on, beside the others added.
  void addOutputs(BaseOutputs outputs) { outputs_.push_back(std::move(outputs)); }

  /// cmd_vel: obeyed from the next frame on. Refused (the reason returned, "" when obeyed): a
  /// NaN/Inf component (zero speed is commanded instead; counted and logged), the e-stop engaged
  /// (counted by the e-stop), an e-stop engaged after the call began (logged).
  std::string commandTwist(const TwistCommand& command);
  /// base/reset: a Reset frame now.
  core::Outcome reset();
  /// base/clear_encoders: a clear-encoders frame now (odometry is not affected).
  core::Outcome clearEncoders();
  /// base/reset_odometry: the pose (and its covariance) back to zero.
  core::Outcome resetOdometry();

  /// Starts the control loop (after the links are started).
  void start() override { controller_.start(); }
  /// Stops the loop and writes a zero-speed frame (before the port closes).
  void shutdown() override { controller_.stop(); }
  core::StatusReport status() override;
  /// Its ~base section: the controller's tunables from its next tick on, the battery limits and
  /// publish_tf at once.
  void retune(const BaseParams& tuned);
  void retune(const params::DriverParams& in_force) override;
  /// Engaged: zero speed held at once (frames keep flowing as the heartbeat), commands refused.
  void attachEStop(core::EStop& e_stop) override;
  /// ~base/use_imu_heading: the heading another device measures (a HeadingSource, the IMU's yaw)
  /// goes to the controller, which only stores it (kinematics::HeadingFusion).
  void useCapabilities(const core::Capabilities& capabilities) override;
  /// The loop and battery poll rates.
  std::string startupSummary() const override;
  /// A command in force or wheels still ramping down.
  std::string motionInForce() const override { return controller_.motionInForce(); }
  bool inMotion() const override { return controller_.inMotion(); }

  /// ~base as started: frames and joint names (the tunables: tuned()).
  const BaseParams& params() const { return params_; }
  /// ~base as last tuned (any thread).
  std::shared_ptr<const BaseParams> tuned() const { return std::atomic_load(&tuned_); }
  const BaseController& controller() const { return controller_; }

 private:
  BaseEvents events();
  void logHeadingSource(kinematics::HeadingSource source);

  core::SerialLink& link_;
  const bool replaying_;    // ~replay_bag: headings arrive stamped with the recording's clock
  const double loop_rate_;  // Hz, as started
  const BaseParams params_;
  std::shared_ptr<const BaseParams> tuned_;  // swapped whole by retune()
  std::vector<BaseOutputs> outputs_;         // added before start(), then only read
  core::LogThrottle timeout_log_{10.0};
  core::LogThrottle silent_log_{10.0};
  core::LogThrottle timeout_error_log_{5.0};
  core::LogThrottle unknown_reply_log_{5.0};
  core::LogThrottle refused_log_{1.0};
  core::LogThrottle voided_log_{1.0};
  core::EStop* e_stop_ = nullptr;  // the node's, set before start()
  BaseController controller_;      // last: its threads use the members above
};

}  // namespace serial_robot_driver::devices::base
