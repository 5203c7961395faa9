// The UART bus servos as a device of the driver, whole and ROS-free: the bus (transactions, the
// move queue, the poll schedule) on its port, the motion claims of the e-stop and the
// trajectories, its statuses, its ~servo_bus tunables and the servo_commands input. Front ends
// attach to it: they call its inputs with core values, register outputs that receive each polled
// servo's state, and serve their servo calls on the bus it owns.
//
// Threading: the outputs are called on the bus's worker (the port's reader thread);
// commandServos() on its caller's thread, never waiting for the bus.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_diagnostics.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/devices/servo_bus/servo_joint_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"

namespace serial_robot_driver::devices::servo_bus {

/// The bus device's configuration: what the parameters bound into ServoBusParams::bus, plus the
/// polled servos (state_ids and the joint_ids servos).
ServoBusConfig makeServoBusConfig(const ServoBusParams& params);

/// A servo call's message, naming the parameter that arms a refused dangerous write.
std::string servoStatusMessage(const ServoStatus& status);

/// A servo_commands message: per named servo ("servo_<id>") a position (rad) and, optionally, a
/// velocity (rad/s; none or 0: ROTATE in ~servo_bus/command_interval_ms).
struct ServoJointCommand {
  std::vector<std::string> names;
  std::vector<double> positions;
  std::vector<double> velocities;
};

/// What a front end receives; every listener may be empty.
struct ServoBusOutputs {
  /// One polled servo's angle as its joint (a joint_ids servo's name and rad, else "servo_<id>"
  /// and the angle in rad), with the answer's arrival time.
  std::function<void(const JointPosition& state, core::Clock::time_point arrival)> servo_state;
};

class ServoBusDevice : public core::Device {
 public:
  /// The bus on `link` (its worker runs on the port's reader thread). `link` must outlive this.
  ServoBusDevice(const params::DriverParams& params, core::SerialLink& link);
  ~ServoBusDevice() override;

  /// Before start(): `outputs` receives the states from then on, beside the others added.
  void addOutputs(ServoBusOutputs outputs) { outputs_.push_back(std::move(outputs)); }

  /// servo_commands: the moves queued for the bus's worker. Refused (the reason returned, "" when
  /// queued, counted and logged): the e-stop engaged, or a command that does not check out
  /// (servo_bus::toServoMoves: counts, names, NaN/Inf). A joint servo under a trajectory is taken
  /// over, and its goal aborted.
  std::string commandServos(const ServoJointCommand& command);

  /// The bus and the motion claims the servo/* calls run on (the front end's services).
  ServoBus& bus() { return bus_; }
  ServoMotionClaims& claims() { return claims_; }

  /// Starts the bus's worker: moves and polls from here on.
  void start() override;
  /// Fails a call in progress and stops the worker. Idempotent.
  void shutdown() override;
  core::StatusReport status() override { return diagnostics_.busStatus(commands_rejected_.load()); }
  /// "servo_bus servo <id>", one status per polled servo, also while ~servo_bus/health_rate is 0
  /// (it may be tuned on): its readings against its own limits (an offline servo is an ERROR),
  /// its identity, a WARN for each setting that does not fit.
  std::vector<NamedStatus> extraStatuses() override;
  /// Its ~servo_bus section: timeout and retries from the next transaction, the poll rate from
  /// the next poll, command_interval_ms from the next servo_commands.
  void retune(const ServoBusParams& tuned);
  void retune(const params::DriverParams& in_force) override;
  /// ~servo_bus/joint_ids as trajectory joints: one queued move per segment.
  std::vector<trajectory::TrajectoryJoints> trajectoryJoints() override;
  /// The servos set moving (ServoBus::motionInForce()).
  std::string motionInForce() const override { return bus_.motionInForce(); }
  bool inMotion() const override { return !bus_.movingIds().empty(); }
  void attachTrajectories(trajectory::TrajectoryExecutor& executor) override {
    claims_.attachTrajectories(executor);
  }
  /// Engaged: queued moves dropped, a SPIN stop to every servo the driver set moving; motion
  /// services and servo_commands refused until it is released (reads, pings, scans still work).
  void attachEStop(core::EStop& e_stop) override;

 private:
  ServoBusEvents makeEvents();

  // Bus servos as joints (trajectories): fixed before the bus starts, read on the worker thread.
  const std::vector<trajectory::BusJoint> bus_joints_;
  const double state_rate_;
  std::vector<ServoBusOutputs> outputs_;  // added before start(), then only read
  core::LogThrottle silent_log_{5.0};
  core::LogThrottle move_failed_log_{5.0};
  core::LogThrottle stop_log_{5.0};
  core::LogThrottle e_stop_log_{5.0};
  core::LogThrottle rejected_log_{5.0};
  ServoBus bus_;
  ServoMotionClaims claims_;                   // the e-stop and the trajectories, over bus_joints_
  std::atomic<uint16_t> command_interval_ms_;  // retune() from the tuning thread
  std::atomic<uint64_t> commands_rejected_{0};
  // servo_states asked vs achieved, between two status updates (the diagnostics thread only).
  ServoBusDiagnostics diagnostics_;
  bool started_ = false;
  bool shut_down_ = false;
};

}  // namespace serial_robot_driver::devices::servo_bus
