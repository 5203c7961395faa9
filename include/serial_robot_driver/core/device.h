// What a device is to the node, in core types only, so every front end (the ROS node today) drives
// every device one way: it is constructed on its port before the ports start, wired (the e-stop,
// the trajectories over its joints, the capabilities it offers and asks for), started once the
// ports run, asked for its status from the diagnostics timer, retuned at run time, and shut down
// (its last words) before the ports close. A front end turns its StatusReports into its own status
// messages in one place (the ROS node: DiagnosticStatus), under the device's registered name.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/core/capabilities.h"
#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/params/driver_params.h"
#include "serial_robot_driver/trajectory/executor.h"
#include "serial_robot_driver/trajectory/joint_groups.h"

namespace serial_robot_driver::core {

class Device {
 public:
  virtual ~Device() = default;

  /// Starts what runs on its own (threads, spinners); called after the ports are started.
  virtual void start() = 0;
  /// Stops taking requests and says its last words while the port is still open. Idempotent.
  virtual void shutdown() = 0;
  /// The device's status now (the diagnostics timer's thread; also after shutdown() for a last
  /// report).
  virtual StatusReport status() = 0;

  /// A status of its own beyond status() (e.g. one per bus servo), under its own name.
  struct NamedStatus {
    std::string name;
    std::function<StatusReport()> report;
  };
  /// Asked once, when the node is built.
  virtual std::vector<NamedStatus> extraStatuses() { return {}; }

  /// Takes its runtime tunables from `in_force` (validated; the rest is what the device was built
  /// with) from its next loop tick or transaction on. Devices without tunables ignore it.
  virtual void retune(const params::DriverParams& /*in_force*/) {}

  /// Its rates worth the node's start-up log line (e.g. "loop 50 Hz, battery poll 1 Hz"), or "".
  virtual std::string startupSummary() const { return {}; }

  /// The joints trajectories may drive on this device (none by default).
  virtual std::vector<trajectory::TrajectoryJoints> trajectoryJoints() { return {}; }
  /// The node's trajectory executor, given before start() when trajectoryJoints() had joints: the
  /// device reports their measurements to it and lets it know when another command takes them.
  /// It outlives the device's threads.
  virtual void attachTrajectories(trajectory::TrajectoryExecutor& /*executor*/) {}
  /// The node's one e-stop, given before start(): the device registers what engaging it means
  /// for its actuators and refuses motion commands while it holds. It outlives the device.
  virtual void attachEStop(EStop& /*e_stop*/) {}
  /// Why this device's actuators may be moving the robot now (a command in force, a ramp not yet
  /// at rest), "" when they are held still. Any thread, cheap: a sensor being calibrated asks it
  /// once per frame.
  virtual std::string motionInForce() const { return {}; }
  /// Whether motionInForce() would name something, without building its text (per frame).
  virtual bool inMotion() const { return !motionInForce().empty(); }

  /// Offers what other devices may use (capabilities.h); before any device asks.
  virtual void offerCapabilities(Capabilities& /*capabilities*/) {}
  /// Asks for what it uses of the others (and the node's MotionQuery); before the links start.
  virtual void useCapabilities(const Capabilities& /*capabilities*/) {}

  /// The inputs it refused (commands, service requests) and its callbacks' errors, by source; the
  /// node reports them in its "e_stop" status. Any thread.
  InputRefusals& inputRefusals() { return input_refusals_; }
  InputRefusalStats inputRefusalStats() const { return input_refusals_.stats(); }

 private:
  InputRefusals input_refusals_;
};

}  // namespace serial_robot_driver::core
