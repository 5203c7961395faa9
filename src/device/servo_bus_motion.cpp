// ServoBusClient's motions: servo/move (CMD 8, 11..15), ROTATE, SPIN and DAMPING, checked before
// anything is written.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/device/servo_bus_client.h"
#include "servo_bus_text.h"

namespace serial_robot_driver::device {

namespace servo = protocol::servo;
using servo::Command;
using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

namespace {

constexpr uint8_t kMaxSpinMode = 3;
constexpr double kDegreesPerTurn = 360.0;

// servo/move limits (vendor SDK and datasheet).
constexpr double kMaxSingleTurnDeg = 180.0;
constexpr double kMaxMultiTurnDeg = 368640.0;  // 1024 turns
constexpr double kMaxVelocityDps = 750.0;
constexpr double kMinVelocityDps = 0.1;  // the wire unit; anything less is sent as 0
constexpr uint16_t kMinRampMs = 20;      // the firmware's shortest ramp
constexpr uint32_t kMaxMultiTurnIntervalMs = 4096000;
}  // namespace

ServoStatus ServoBusClient::move(const MoveRequest& request, BusPriority priority) {
  const auto invalid = [](const std::string& text) {
    return fail(ServoError::kInvalidArgument, text);
  };
  if (!std::isfinite(request.angle_deg)) return invalid("angle_deg is not a finite number");
  if (!std::isfinite(request.velocity_dps)) return invalid("velocity_dps is not a finite number");
  const double max_angle = request.multi_turn ? kMaxMultiTurnDeg : kMaxSingleTurnDeg;
  if (std::fabs(request.angle_deg) > max_angle) {
    return invalid("angle_deg " + formatNumber(request.angle_deg) + " is out of range +-" +
                   formatNumber(max_angle) + " deg for a " +
                   (request.multi_turn ? "multi-turn" : "single-turn") + " move");
  }
  if (request.velocity_dps < 0) {
    return invalid("velocity_dps " + formatNumber(request.velocity_dps) +
                   " is negative (0: not by velocity; the sign of the motion is the angle's)");
  }
  const bool by_velocity = request.velocity_dps > 0;
  const bool with_ramps = by_velocity || request.accel_ms > 0 || request.decel_ms > 0;
  if (by_velocity && request.velocity_dps > kMaxVelocityDps) {
    return invalid("velocity_dps " + formatNumber(request.velocity_dps) +
                   " is above the servo's 750 deg/s");
  }
  if (by_velocity && request.velocity_dps < kMinVelocityDps) {
    return invalid("velocity_dps " + formatNumber(request.velocity_dps) +
                   " is below 0.1 deg/s, the unit on the wire");
  }
  for (const auto& [name, ramp] :
       {std::pair<const char*, uint16_t>{"accel_ms", request.accel_ms},
        std::pair<const char*, uint16_t>{"decel_ms", request.decel_ms}}) {
    if (ramp > 0 && ramp < kMinRampMs) {
      return invalid(std::string(name) + " " + std::to_string(ramp) +
                     " is under 20 ms, the shortest ramp the servo runs (0: not given)");
    }
  }
  const uint32_t max_interval =
      request.multi_turn ? kMaxMultiTurnIntervalMs : std::numeric_limits<uint16_t>::max();
  if (!by_velocity && request.interval_ms > max_interval) {
    return invalid("interval_ms " + std::to_string(request.interval_ms) + " is above " +
                   std::to_string(max_interval) + " ms for a " +
                   (request.multi_turn ? "multi-turn" : "single-turn") + " move");
  }
  servo::MoveRamps ramps;
  ramps.accel_ms = std::max(request.accel_ms, kMinRampMs);
  ramps.decel_ms = std::max(request.decel_ms, kMinRampMs);
  ramps.power_mw = request.power_mw;
  if (with_ramps && !by_velocity && request.interval_ms < ramps.accel_ms + ramps.decel_ms) {
    return invalid("interval_ms " + std::to_string(request.interval_ms) +
                   " is shorter than accel + decel (" +
                   std::to_string(ramps.accel_ms + ramps.decel_ms) + " ms)");
  }

  // On the wire as the vendor SDK puts them: int(value * 10), truncated toward zero.
  const auto angle = static_cast<int32_t>(std::trunc(request.angle_deg * kDecidegreesPerDegree));
  const auto velocity =
      static_cast<uint16_t>(std::trunc(request.velocity_dps * kDecidegreesPerDegree));
  servo::MoveCommand command;
  command.id = request.id;
  command.angle_decidegrees = angle;
  command.interval_ms = request.interval_ms;
  command.velocity_decidegrees_per_s = velocity;
  command.ramps = ramps;
  if (by_velocity) {
    command.cmd = request.multi_turn ? Command::kMultiTurnMoveByVelocity : Command::kMoveByVelocity;
  } else if (with_ramps) {
    command.cmd = request.multi_turn ? Command::kMultiTurnMoveByInterval : Command::kMoveByInterval;
  } else {
    command.cmd = request.multi_turn ? Command::kMultiTurnMove : Command::kRotate;
  }
  const std::vector<uint8_t> frame = servo::encodeMove(command);
  if (!takeBus(priority)) {
    return fail(ServoError::kPreempted, std::string(commandName(command.cmd)) + " to " +
                                            servoName(request.id) + " gave way to a stop");
  }
  std::lock_guard<BusMutex> bus(bus_mutex_, std::adopt_lock);
  return sendCommand(frame, command.cmd, request.id, FrameGate::kMotion);
}

ServoStatus ServoBusClient::rotate(const RotateRequest& request) {
  if (!std::isfinite(request.angle_deg)) {
    return fail(ServoError::kInvalidArgument, "angle is not a finite number");
  }
  const double decidegrees = std::round(request.angle_deg * kDecidegreesPerDegree);
  if (decidegrees < std::numeric_limits<int16_t>::min() ||
      decidegrees > std::numeric_limits<int16_t>::max()) {
    char text[96];
    std::snprintf(text, sizeof(text), "angle %.1f deg is out of range -3276.8 .. 3276.7 deg",
                  request.angle_deg);
    return fail(ServoError::kInvalidArgument, text);
  }
  if (request.wait) {
    if (auto rejection = rejectBroadcast(request.id, Command::kRotate)) return *rejection;
  }
  const std::vector<uint8_t> frame = servo::encodeRotate(
      request.id, static_cast<int16_t>(decidegrees), request.interval_ms, request.power_mw);
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return sendMotion(frame, Command::kRotate, request.id, request.wait,
                    std::chrono::milliseconds(request.interval_ms), FrameGate::kMotion);
}

ServoStatus ServoBusClient::spin(const SpinRequest& request) {
  if (request.mode > kMaxSpinMode) {
    return fail(ServoError::kInvalidArgument,
                "spin mode " + std::to_string(request.mode) +
                    " is out of range 0..3 (0 stop, 1 continuous, 2 turns, 3 milliseconds)");
  }
  const auto mode = static_cast<servo::SpinMode>(request.mode);
  std::chrono::milliseconds motion_time{0};
  if (request.wait) {
    if (auto rejection = rejectBroadcast(request.id, Command::kSpin)) return *rejection;
    double expected_ms = 0.0;
    if (mode == servo::SpinMode::kDurationMs) {
      expected_ms = request.value;
    } else if (mode == servo::SpinMode::kTurns && request.speed_dps > 0) {
      expected_ms = request.value * kDegreesPerTurn * 1000.0 / request.speed_dps;
    }
    // A service must not hang: long spins are started without waiting and polled instead.
    if (expected_ms > kMaxMotionWait.count()) {
      char text[160];
      std::snprintf(text, sizeof(text),
                    "waiting for this SPIN would block the servo bus for about %.0f s (limit "
                    "%.1f s); call it with wait = false",
                    expected_ms / 1000.0, kMaxMotionWait.count() / 1000.0);
      return fail(ServoError::kInvalidArgument, text);
    }
    motion_time = std::chrono::milliseconds(std::llround(expected_ms));
  }
  const std::vector<uint8_t> frame =
      servo::encodeSpin(request.id, request.clockwise, mode, request.speed_dps, request.value);
  std::lock_guard<BusMutex> bus(bus_mutex_);
  // A SPIN stop is what the e-stop itself sends: never held back.
  const FrameGate gate =
      mode == servo::SpinMode::kStop ? FrameGate::kSafetyAction : FrameGate::kMotion;
  return sendMotion(frame, Command::kSpin, request.id, request.wait, motion_time, gate);
}

ServoStatus ServoBusClient::damping(uint8_t id, uint16_t power_mw, bool wait, FrameGate gate) {
  if (wait) {
    if (auto rejection = rejectBroadcast(id, Command::kDamping)) return *rejection;
  }
  const std::vector<uint8_t> frame = servo::encodeDamping(id, power_mw);
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return sendMotion(frame, Command::kDamping, id, wait, std::chrono::milliseconds(0), gate);
}

}  // namespace serial_robot_driver::device
