// The shape every ROS-side device (or input) has, so DriverNode handles them all one way: each is
// constructed on its port before the ports start (it registers its listener, topics and services
// there), started once the ports run, and shut down before the ports close. DriverNode adds its
// diagnostic status under the device's name it was registered under (device/device_module.h).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>

#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/device/e_stop.h"
#include "serial_robot_driver/device/input_refusals.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::trajectory {
struct TrajectoryJoints;
}  // namespace serial_robot_driver::trajectory

namespace serial_robot_driver::ros_layer {

class TrajectoryServer;
using trajectory::TrajectoryJoints;

class DeviceInterface {
 public:
  virtual ~DeviceInterface() = default;
  /// Starts what runs on its own (threads, spinners); called after the ports are started.
  virtual void start() = 0;
  /// Stops taking requests and says its last words while the port is still open. Idempotent.
  virtual void shutdown() = 0;
  /// Fills the device's diagnostic status (called from the diagnostics timer, also after
  /// shutdown() for a last report).
  virtual void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) = 0;
  /// Takes the runtime-tunable parameters of `params` (validated; the rest is what the device
  /// was built with) from its next loop tick or transaction on (dynamic_reconfigure, see
  /// ros/runtime_tuning.h). Devices without tunables ignore it.
  virtual void retune(const DriverParams& /*params*/) {}
  /// The joints trajectories may drive on this device (none by default).
  virtual std::vector<TrajectoryJoints> trajectoryJoints();
  /// The node's trajectory server, given before start() when trajectoryJoints() had joints: the
  /// device reports their measurements to it and lets it know when another command takes them.
  virtual void attachTrajectories(TrajectoryServer* /*server*/) {}
  /// The node's one e-stop, given before start(): the device registers what engaging it means
  /// for its actuators and refuses motion commands while it holds. It outlives the device.
  virtual void attachEStop(device::EStop& /*e_stop*/) {}
  /// Why this device's actuators may be moving the robot now (a command in force, a ramp not yet
  /// at rest), "" when they are held still. Any thread, cheap: a sensor being calibrated asks it
  /// once per frame.
  virtual std::string motionInForce() const { return {}; }
  /// Asks every device of the node motionInForce() ("<device>: <why>", or ""). Given before the
  /// links start to a device whose sensor must only be calibrated while the robot is still.
  using MotionQuery = std::function<std::string()>;
  virtual void setMotionQuery(MotionQuery /*query*/) {}
  /// Statuses of its own beyond the device's one (e.g. one per bus servo), added to `updater`
  /// once, at construction of the node.
  virtual void addDiagnostics(diagnostic_updater::Updater& /*updater*/) {}

  /// The inputs of its topics and services it refused, and its callbacks' errors, by source
  /// (ros/guarded_callbacks.h); the node reports them in its "e_stop" status. Any thread.
  device::InputRefusals& inputRefusals() { return input_refusals_; }
  device::InputRefusalStats inputRefusalStats() const { return input_refusals_.stats(); }

 private:
  device::InputRefusals input_refusals_;
};

}  // namespace serial_robot_driver::ros_layer
