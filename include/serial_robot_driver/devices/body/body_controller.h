// The servo controller board (docs/protocols.md, section 2), ROS-free: telemetry frames in, goal
// positions out as one Dynamixel 2.0 sync-write frame.
//
// Threading: onFrame() runs on the link's reader thread and calls on_telemetry right there (no
// queue, so a message is published as soon as its frame is complete), without the lock held.
// sendJointCommand() may be called from any thread; it serializes on mutex_, which also guards the
// stats (stats() returns a snapshot).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/core/motion_gate.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/protocol/decode_result.h"

namespace serial_robot_driver::devices::body {

/// Maps one servo's raw ticks to a joint angle and back:
///   position [rad] = direction * (ticks - zero_ticks) * 2 pi / ticks_per_revolution
///   velocity [rad/s] = direction * velocity_scale * raw, or, when velocity_scale is 0,
///                      direction * raw * 2 pi / ticks_per_revolution (raw read as ticks/s).
struct JointCalibration {
  int zero_ticks = 2048;
  int direction = 1;  ///< +1 or -1
  int ticks_per_revolution = 4096;
  double velocity_scale = 0.0;  ///< rad/s per raw speed unit; 0: raw is ticks/s

  double toRadians(uint16_t ticks) const;
  double toRadiansPerSecond(int16_t raw_speed) const;
  /// The inverse of toRadians(), rounded to the nearest tick. std::nullopt for NaN or infinity
  /// and for a position the servo cannot reach: outside 0 .. ticks_per_revolution - 1 (one turn of
  /// its position encoder) or 0..65535.
  std::optional<uint16_t> toTicks(double radians) const;
  /// The reachable positions in rad, for messages: [lowest, highest] (ordered).
  std::pair<double, double> reachableRadians() const;
};

/// One joint of the board, in telemetry / sync-write order.
struct BodyJoint {
  std::string name;
  uint8_t servo_id = 0;
  JointCalibration calibration;
};

struct BodyStats {
  uint64_t frames_decoded = 0;
  uint64_t decode_errors = 0;  ///< verified telemetry frames that still did not decode (e.g. LEN)
  std::optional<protocol::DecodeError> last_decode_error;
  uint64_t commands_sent = 0;
  uint64_t commands_rejected = 0;  ///< invalid commands: nothing was written
  uint64_t write_failures = 0;     ///< valid commands the link refused (port down)
  uint64_t motion_refused = 0;     ///< valid commands the motion gate refused (e-stop, shutdown)
  /// Of motion_refused: accepted before an e-stop that engaged before their write (even one
  /// released since): an e-stop voids everything accepted before it.
  uint64_t motion_voided = 0;
  uint64_t joints_out_of_range = 0;  ///< joint targets left out: beyond what the servo can reach
};

enum class JointCommandStatus {
  kSent,
  kEmpty,           ///< no joint named (nothing to do, nothing written)
  kLengthMismatch,  ///< names and positions differ in length
  kUnknownJoint,    ///< a name that is not one of the configured joints
  kDuplicateJoint,  ///< the same joint named twice in one command
  kNotFinite,       ///< a NaN or infinite position
  kOutOfRange,      ///< every named joint was beyond its servo's reach: nothing written
  kWriteFailed,     ///< valid, but the link refused the frame (port down)
  kMotionRefused,   ///< valid, but the motion gate was locked (e-stop) or closed when written
  kMotionVoided,    ///< valid, but an e-stop engaged after it was accepted (even if released)
};

/// What became of one joint command: the ROS layer logs message() (throttled) when !ok().
struct JointCommandResult {
  JointCommandStatus status = JointCommandStatus::kSent;
  std::string joint;  ///< the offending joint, when the status is about one
  /// Joints left out of a sent command because their target is beyond the servo's reach; the
  /// other joints were sent. Each entry says which joint and what it can take.
  std::vector<std::string> out_of_range;

  bool ok() const { return status == JointCommandStatus::kSent; }
  std::string message() const;

 private:
  std::string outOfRangeText() const;
};

/// What the body reports; every hook may be empty. Called without the controller's lock held.
struct BodyEvents {
  /// Called on the reader thread for every decoded telemetry frame with its arrival time.
  using TelemetryCallback =
      std::function<void(const Telemetry& telemetry, core::Clock::time_point arrival)>;
  TelemetryCallback on_telemetry;
};

class BodyController : public core::LinkListener {
 public:
  /// `joints` in frame order (the order of ~body/servo_ids).
  BodyController(std::vector<BodyJoint> joints, core::FrameWriter writer, BodyEvents events = {});

  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               core::Clock::time_point arrival) override;

  /// Validates a command (positions in rad) and writes one sync-write frame in servo_ids order.
  ///
  /// Joints the command does not name are sent again at their last commanded position, so a
  /// partial command never moves the other joints. Joints that were never commanded are left out
  /// of the frame: the driver cannot know a safe target for them, and a servo that is not
  /// addressed keeps whatever it is doing. An invalid command writes nothing and changes no stored
  /// position. A joint whose target the servo cannot reach is left out (its servo keeps its last
  /// commanded position) and listed in out_of_range; the other joints are sent.
  ///
  /// `accepted`: the gate's generation() when the command was accepted (before its e-stop check);
  /// an e-stop engaged since voids it (kMotionVoided), released or not. Unset: accepted now.
  JointCommandResult sendJointCommand(const std::vector<std::string>& names,
                                      const std::vector<double>& positions,
                                      std::optional<core::MotionGate::Generation> accepted = {});

  /// The gate every sync-write passes when it is written (see motion_gate.h): the e-stop locks
  /// it, the shutdown closes it.
  core::MotionGate& gate() { return gate_; }
  /// The position (rad) joint `joint_index` (frame order) was last commanded, i.e. what the
  /// board was last sent for it; nothing when it never was (or for an index beyond the joints).
  std::optional<double> lastCommandedPosition(std::size_t joint_index) const;

  /// How long a written joint command counts as motion: the board's servos take their own time to
  /// reach a target (a sensor calibration then waits its settle time on top).
  static constexpr std::chrono::milliseconds kJointCommandMotion{500};
  /// Why the joints may be moving at `now`: a joint command written less than kJointCommandMotion
  /// before it; "" when none was. Any thread.
  std::string motionInForce(core::Clock::time_point now) const;
  /// Whether motionInForce(now) would name something, without building its text. Any thread.
  bool inMotion(core::Clock::time_point now) const;

  const std::vector<BodyJoint>& joints() const { return joints_; }
  std::size_t servoCount() const { return joints_.size(); }
  BodyStats stats() const;

 private:
  /// Requires mutex_: a joint command written less than kJointCommandMotion before `now`.
  bool writtenLatelyLocked(core::Clock::time_point now) const;
  /// Sync-writes `targets` through the motion gate (mutex_ held): kSent, or why not (counted).
  JointCommandStatus writeTargetsLocked(const std::vector<ServoTarget>& targets,
                                        core::MotionGate::Generation generation);

  const std::vector<BodyJoint> joints_;
  const core::FrameWriter writer_;
  const BodyEvents events_;

  core::MotionGate gate_;

  mutable std::mutex mutex_;  // guards the fields below
  std::vector<std::optional<uint16_t>> last_commanded_ticks_;
  std::optional<core::Clock::time_point> last_written_;  ///< the last sync-write that went out
  BodyStats stats_;
};

}  // namespace serial_robot_driver::devices::body
