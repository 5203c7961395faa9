// The seam between the trajectory executor and a device, ROS-free: which joints a device has, what
// they can reach and how they are set, either streamed (one frame per loop tick) or one move per
// segment; each device builds its own in its folder. Also the steady clock trajectories run on and
// where a stop holds a streamed joint.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/trajectory/command.h"

namespace serial_robot_driver::trajectory {

/// What a device gives the trajectory executor: its joints and how to set their positions, either
/// streamed (`write` every loop tick) or one move per segment (`move`).
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
  /// The device's e-stop generation now (core::MotionGate::generation()): noted when a
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

}  // namespace serial_robot_driver::trajectory
