// The seam between the trajectory executor and a device, ROS-free: which joints a device has, what
// they can reach and how they are set, either streamed (the body: one frame per loop tick) or one
// move per segment (the UART bus servos used as joints, ~servo_bus/joint_ids ...). Also the steady
// clock trajectories run on and where a stop holds a streamed joint.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/trajectory/bus_joint.h"
#include "serial_robot_driver/trajectory/command.h"

namespace serial_robot_driver::trajectory {

/// What a device gives the trajectory executor: its joints and how to set their positions, either
/// streamed (`write` every loop tick: the body) or one move per segment (`move`: bus servos).
struct TrajectoryJoints {
  std::vector<JointRange> joints;
  /// A goal aborts when one of its joints has had no measurement for this long (s).
  double state_timeout = 0.5;
  /// Writes one frame setting these joints (rad), accepted under e-stop generation `accepted`
  /// (see `generation`; unset: now): a frame an e-stop voided is not written. Returns an error
  /// text, empty when written.
  std::function<std::string(const std::vector<std::string>& names,
                            const std::vector<double>& positions, std::optional<uint64_t> accepted)>
      write;
  /// The device's e-stop generation now (device::MotionGate::generation()): noted when a
  /// trajectory is accepted and handed to `write`, so that one accepted before an e-stop never
  /// moves a joint after it. May be empty (nothing is voided by generation).
  std::function<uint64_t()> generation;
  /// Instead of `write`: moves joint `index` (into `joints`) to `position` (rad) in `duration` s;
  /// must not block (queue the frame). Returns an error text, empty when queued.
  std::function<std::string(std::size_t index, double position, double duration)> move;
  /// Streamed joints: the position (rad) the device last commanded joint `index`, by whatever
  /// command; nothing when it never did. May be empty.
  std::function<std::optional<double>(std::size_t index)> last_commanded;
  /// Per-segment joints: stops joint `index` where it is, with no position (how a stop holds it);
  /// must not block. Returns an error text, empty when queued. May be empty (nothing is sent).
  std::function<std::string(std::size_t index)> stop;
};

/// The trajectory clock: seconds of std::chrono::steady_clock.
double steadyNow();

/// Where a stop holds a streamed joint: the position the executor last wrote, else the device's
/// last command, else the measurement when it is fresh (pass nothing when stale); nothing: leave it
/// alone (no default, no old end point).
std::optional<double> streamedHoldPosition(std::optional<double> last_written,
                                           std::optional<double> last_commanded,
                                           std::optional<double> fresh_measurement);

/// The body's joints (~body/joint_names) and their reach; a write is one sync-write frame through
/// BodyController::sendJointCommand (ticks rounded as joint_commands rounds them). `controller`
/// must outlive the result.
TrajectoryJoints bodyTrajectoryJoints(device::BodyController& controller);

/// The joint of bus servo `id`, if it is one.
const BusJoint* findBusJoint(const std::vector<BusJoint>& joints, uint8_t id);

/// Queues a move of servo `id` to `angle_deg` (single-turn) in `interval_ms`; must not block.
/// Returns an error text, empty when queued.
using QueueServoMove =
    std::function<std::string(uint8_t id, double angle_deg, uint32_t interval_ms)>;

/// Stops servo `id` where it is (a SPIN stop, no position); must not block. Returns an error
/// text, empty when queued.
using StopServo = std::function<std::string(uint8_t id)>;

/// How long a bus joint may go without a poll answer before its goal aborts: three poll periods at
/// `state_rate` (Hz), at least 0.5 s.
double busStateTimeout(double state_rate);

/// The bus joints for the trajectory executor: one ROTATE per segment, at its start, with the
/// segment's remaining duration as interval; a stop holds a joint with `stop_servo` (may be
/// empty: nothing is sent). Its state_timeout is busStateTimeout(state_rate).
TrajectoryJoints busTrajectoryJoints(const std::vector<BusJoint>& joints, QueueServoMove queue_move,
                                     double state_rate, StopServo stop_servo = {});

}  // namespace serial_robot_driver::trajectory
