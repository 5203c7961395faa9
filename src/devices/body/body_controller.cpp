#include "serial_robot_driver/devices/body/body_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace serial_robot_driver::devices::body {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;

double radiansPerTick(const JointCalibration& calibration) {
  return kTwoPi / static_cast<double>(calibration.ticks_per_revolution);
}

}  // namespace

double JointCalibration::toRadians(uint16_t ticks) const {
  return direction * (static_cast<double>(ticks) - zero_ticks) * radiansPerTick(*this);
}

double JointCalibration::toRadiansPerSecond(int16_t raw_speed) const {
  if (velocity_scale != 0.0) return direction * velocity_scale * raw_speed;
  return direction * raw_speed * radiansPerTick(*this);
}

namespace {
double highestTick(const JointCalibration& calibration) {
  return std::min<double>(calibration.ticks_per_revolution - 1,
                          std::numeric_limits<uint16_t>::max());
}
}  // namespace

std::optional<uint16_t> JointCalibration::toTicks(double radians) const {
  if (!std::isfinite(radians)) return std::nullopt;
  // direction is +-1, so dividing by it is multiplying by it.
  const double ticks = std::round(zero_ticks + direction * radians / radiansPerTick(*this));
  // Never clamp: a clamped target is a position nobody asked for.
  if (ticks < 0.0 || ticks > highestTick(*this)) return std::nullopt;
  return static_cast<uint16_t>(ticks);
}

std::pair<double, double> JointCalibration::reachableRadians() const {
  const double a = toRadians(0);
  const double b = toRadians(static_cast<uint16_t>(highestTick(*this)));
  return {std::min(a, b), std::max(a, b)};
}

std::string JointCommandResult::outOfRangeText() const {
  std::string text;
  for (const std::string& entry : out_of_range) text += (text.empty() ? "" : "; ") + entry;
  return text;
}

std::string JointCommandResult::message() const {
  switch (status) {
    case JointCommandStatus::kSent:
      if (!out_of_range.empty()) {
        return "joint command sent without the joints beyond their servo's reach (" +
               outOfRangeText() + ")";
      }
      return "sent";
    case JointCommandStatus::kEmpty:
      return "joint command names no joint";
    case JointCommandStatus::kLengthMismatch:
      return "joint command has different numbers of names and positions";
    case JointCommandStatus::kUnknownJoint:
      return "joint command names unknown joint '" + joint + "'";
    case JointCommandStatus::kDuplicateJoint:
      return "joint command names joint '" + joint + "' more than once";
    case JointCommandStatus::kNotFinite:
      return "joint command has a NaN or infinite position for joint '" + joint + "'";
    case JointCommandStatus::kOutOfRange:
      return "joint command not written: every target is beyond its servo's reach (" +
             outOfRangeText() + ")";
    case JointCommandStatus::kWriteFailed:
      return "joint command not written: the body port is not connected";
    case JointCommandStatus::kMotionRefused:
      return "joint command not written: e_stop engaged or shutting down";
    case JointCommandStatus::kMotionVoided:
      return std::string("joint command not written: ") + core::toString(core::GateState::kVoided);
  }
  return "unknown joint command status";
}

BodyController::BodyController(std::vector<BodyJoint> joints, core::FrameWriter writer,
                               BodyEvents events)
    : joints_(std::move(joints)),
      writer_(std::move(writer)),
      events_(std::move(events)),
      last_commanded_ticks_(joints_.size()) {}

void BodyController::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                             core::Clock::time_point arrival) {
  // A shared port hands every listener every frame: only telemetry is ours.
  if (family != kTelemetryFrames) return;
  const auto telemetry = decodeTelemetry(data, size, joints_.size());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!telemetry) {
      ++stats_.decode_errors;
      stats_.last_decode_error = telemetry.error();
      return;
    }
    ++stats_.frames_decoded;
  }
  if (events_.on_telemetry) events_.on_telemetry(*telemetry, arrival);
}

namespace {

/// "head_pan: 4.000 rad is outside -3.142 .. 3.138 rad"
std::string outOfReachText(const std::string& name, double position,
                           const JointCalibration& calibration) {
  const auto [low, high] = calibration.reachableRadians();
  char text[160];
  std::snprintf(text, sizeof(text), "%s: %.3f rad is outside %.3f .. %.3f rad", name.c_str(),
                position, low, high);
  return text;
}

/// Checks the whole command before anything is touched (a bad command must not half-apply) and
/// fills `requested` by joint index with the ticks of every reachable target.
JointCommandResult resolveTargets(const std::vector<BodyJoint>& joints,
                                  const std::vector<std::string>& names,
                                  const std::vector<double>& positions,
                                  std::vector<std::optional<uint16_t>>* requested) {
  JointCommandResult result;
  if (names.empty()) {
    result.status = JointCommandStatus::kEmpty;
    return result;
  }
  if (names.size() != positions.size()) {
    result.status = JointCommandStatus::kLengthMismatch;
    return result;
  }
  // Every joint named so far, whatever its value: an out-of-range target leaves requested[]
  // empty, so requested[] alone would let a second occurrence of that name through.
  std::vector<bool> named(joints.size(), false);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto joint = std::find_if(joints.begin(), joints.end(),
                                    [&](const BodyJoint& j) { return j.name == names[i]; });
    result.joint = names[i];
    if (joint == joints.end()) {
      result.status = JointCommandStatus::kUnknownJoint;
      return result;
    }
    const std::size_t index = static_cast<std::size_t>(joint - joints.begin());
    if (named[index]) {
      result.status = JointCommandStatus::kDuplicateJoint;
      return result;
    }
    named[index] = true;
    if (!std::isfinite(positions[i])) {
      result.status = JointCommandStatus::kNotFinite;
      return result;
    }
    (*requested)[index] = joint->calibration.toTicks(positions[i]);
    if (!(*requested)[index]) {
      // Left out, not clamped: the servo keeps its last target instead of an invented one.
      result.out_of_range.push_back(outOfReachText(names[i], positions[i], joint->calibration));
    }
  }
  result.joint.clear();
  if (result.out_of_range.size() == names.size()) result.status = JointCommandStatus::kOutOfRange;
  return result;
}

}  // namespace

JointCommandResult BodyController::sendJointCommand(
    const std::vector<std::string>& names, const std::vector<double>& positions,
    std::optional<core::MotionGate::Generation> accepted) {
  // Noted before waiting for the lock: an e-stop while this command waits voids it.
  const core::MotionGate::Generation generation = accepted.value_or(gate_.generation());
  std::vector<std::optional<uint16_t>> requested(joints_.size());
  JointCommandResult result = resolveTargets(joints_, names, positions, &requested);

  std::lock_guard<std::mutex> lock(mutex_);
  stats_.joints_out_of_range += result.out_of_range.size();
  if (!result.ok()) {
    ++stats_.commands_rejected;
    return result;
  }
  // A joint not in this command keeps the target last sent for it.
  std::vector<ServoTarget> targets;
  targets.reserve(joints_.size());
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    const std::optional<uint16_t> ticks = requested[i] ? requested[i] : last_commanded_ticks_[i];
    if (ticks) targets.push_back({joints_[i].servo_id, *ticks});
  }
  result.status = writeTargetsLocked(targets, generation);
  if (!result.ok()) return result;
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (requested[i]) last_commanded_ticks_[i] = requested[i];
  }
  last_written_ = core::Clock::now();
  ++stats_.commands_sent;
  return result;
}

JointCommandStatus BodyController::writeTargetsLocked(const std::vector<ServoTarget>& targets,
                                                      core::MotionGate::Generation generation) {
  // Writing under the lock keeps frames in the order their positions were stored; through the
  // gate, so a command that waited for this lock is refused if the e-stop came meanwhile.
  bool written = false;
  const core::GateState gate = gate_.writeIfOpen(
      [&] { return writer_ && writer_(encodeSyncWrite(targets)); }, &written, generation);
  if (gate != core::GateState::kOpen) {
    ++stats_.motion_refused;
    const bool voided = gate == core::GateState::kVoided;
    if (voided) ++stats_.motion_voided;
    return voided ? JointCommandStatus::kMotionVoided : JointCommandStatus::kMotionRefused;
  }
  if (!written) {
    ++stats_.write_failures;
    return JointCommandStatus::kWriteFailed;
  }
  return JointCommandStatus::kSent;
}

bool BodyController::writtenLatelyLocked(core::Clock::time_point now) const {
  return last_written_ && now - *last_written_ < kJointCommandMotion;
}

bool BodyController::inMotion(core::Clock::time_point now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return writtenLatelyLocked(now);
}

std::string BodyController::motionInForce(core::Clock::time_point now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!writtenLatelyLocked(now)) return {};
  char text[96];
  std::snprintf(text, sizeof text, "joint command written %.2f s ago",
                std::chrono::duration<double>(now - *last_written_).count());
  return text;
}

std::optional<double> BodyController::lastCommandedPosition(std::size_t joint_index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (joint_index >= last_commanded_ticks_.size() || !last_commanded_ticks_[joint_index]) {
    return std::nullopt;
  }
  return joints_[joint_index].calibration.toRadians(*last_commanded_ticks_[joint_index]);
}

BodyStats BodyController::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace serial_robot_driver::devices::body
