#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "servo_bus_text.h"

namespace serial_robot_driver::devices::servo_bus {

using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

namespace {

constexpr uint8_t kMaxSpinMode = 3;
constexpr double kDegreesPerTurn = 360.0;

constexpr uint8_t kBaudrateParam = dataId(ServoDataId::kBaudrate);
constexpr std::size_t kReadDataHeader = 2;  // id, data_id, then the value

ServoStatus fromWriteCheck(WriteCheck check, const ParamInfo& param, int64_t value) {
  ServoError error = ServoError::kInvalidArgument;
  switch (check) {
    case WriteCheck::kOk:
      return ok("");
    case WriteCheck::kReadOnly:
      error = ServoError::kReadOnly;
      break;
    case WriteCheck::kOutOfRange:
      error = ServoError::kOutOfRange;
      break;
    case WriteCheck::kDangerous:
      error = ServoError::kDangerous;
      break;
  }
  // The switch that arms dangerous writes is named by the caller's layer (a ROS parameter there).
  return fail(error, describe(check, param, value));
}

ServoParamValue toParamValue(const ParamInfo& param, int64_t raw) {
  // The table's units are already engineering units (mV, mA, mW, degC, ms, 0.1deg): no scaling.
  return ServoParamValue{std::string(param.name), param.data_id, raw, std::string(param.unit)};
}

ServoStatus gaveWayToAStop(Command cmd, uint8_t id) {
  return fail(ServoError::kPreempted,
              std::string(commandName(cmd)) + " to " + servoName(id) + " gave way to a stop");
}

std::string valueText(const ServoParamValue& value) {
  std::string text = std::to_string(value.value);
  if (!value.unit.empty()) text += " " + value.unit;
  return text;
}

}  // namespace

ServoBusClient::ServoBusClient(ServoBusOptions options, core::FrameWriter writer)
    : transactions_(std::move(options), std::move(writer)) {}

// Queries: PING, scan, READ_ANGLE and the multi-turn angle.

ServoStatus ServoBusClient::pingLocked(uint8_t id) {
  Packet answer;
  const ServoStatus status =
      transactions_.exchangeLocked(encodePing(id), Expectation(Command::kPing, id), &answer);
  if (!status.ok()) return status;
  return ok(servoName(id) + " is online (" + status.message + ")");
}

ServoStatus ServoBusClient::ping(uint8_t id) {
  if (auto rejection = rejectBroadcast(id, Command::kPing)) return *rejection;
  std::lock_guard<BusMutex> bus(transactions_.busMutex());
  return pingLocked(id);
}

ServoStatus ServoBusClient::readAngle(uint8_t id, double* angle_deg,
                                      core::Clock::time_point* arrival, BusPriority priority) {
  if (auto rejection = rejectBroadcast(id, Command::kReadAngle)) return *rejection;
  Packet answer;
  core::Clock::time_point answered_at;
  ServoStatus status;
  const std::vector<uint8_t> request = encodeReadAngle(id);
  const Expectation expect(Command::kReadAngle, id);
  if (!transactions_.takeBus(priority)) {
    return fail(ServoError::kPreempted, servoName(id) + "'s READ_ANGLE gave way to a stop");
  }
  {
    std::lock_guard<BusMutex> bus(transactions_.busMutex(), std::adopt_lock);
    // Background work makes one attempt: the next poll is the retry.
    const ServoBusOptions options = transactions_.options();
    const int attempts = priority == BusPriority::kBackground ? 1 : options.retries + 1;
    status = transactions_.transact(request, expect, options.timeout, attempts, &answer,
                                    FrameGate::kSafetyAction, priority == BusPriority::kWorker,
                                    &answered_at);
  }
  if (!status.ok()) return status;
  const protocol::Decoded<AngleAnswer> decoded = decodeAngleAnswer(answer);
  if (!decoded) return fail(ServoError::kBadAnswer, servoName(id) + " sent an unreadable angle");
  if (arrival != nullptr) *arrival = answered_at;
  *angle_deg = decoded->angle_decidegrees / kDecidegreesPerDegree;
  // The poll reads no message: it would cost a formatted string on every transaction.
  if (priority == BusPriority::kBackground) return ok({});
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f deg", *angle_deg);
  return ok(servoName(id) + " is at " + text);
}

ServoStatus ServoBusClient::readMultiTurnAngle(uint8_t id, MultiTurnReading* reading) {
  if (auto rejection = rejectBroadcast(id, Command::kReadMultiTurnAngle)) return *rejection;
  Packet answer;
  const ServoStatus status = transactions_.exchange(
      encodeReadMultiTurnAngle(id), Expectation(Command::kReadMultiTurnAngle, id), &answer);
  if (!status.ok()) return status;
  const protocol::Decoded<MultiTurnAngle> decoded = decodeMultiTurnAngle(answer);
  if (!decoded) {
    return fail(ServoError::kBadAnswer, servoName(id) + " sent an unreadable multi-turn angle");
  }
  reading->angle_deg = decoded->angle_decidegrees / kDecidegreesPerDegree;
  reading->turns = decoded->turns;
  char text[64];
  std::snprintf(text, sizeof(text), "%.1f deg (%d turns)", reading->angle_deg, reading->turns);
  return ok(servoName(id) + " is at " + text);
}

ServoStatus ServoBusClient::pingOnceLocked(uint8_t id) {
  Packet answer;
  return transactions_.transact(encodePing(id), Expectation(Command::kPing, id),
                                transactions_.options().timeout, 1, &answer);
}

ServoStatus ServoBusClient::scan(uint8_t first_id, uint8_t last_id, std::vector<uint8_t>* ids) {
  if (first_id > last_id) {
    return fail(ServoError::kInvalidArgument, "first_id " + std::to_string(first_id) +
                                                  " is above last_id " + std::to_string(last_id));
  }
  if (last_id == kBroadcastId) {
    return fail(ServoError::kInvalidArgument,
                "id 255 is the broadcast address and cannot be scanned (ids 0..254)");
  }
  ids->clear();
  for (int id = first_id; id <= last_id; ++id) {
    // The bus is taken per id: a service call or a poll waits for one PING at most.
    std::lock_guard<BusMutex> bus(transactions_.busMutex());
    const ServoStatus status = pingOnceLocked(static_cast<uint8_t>(id));
    if (status.ok()) {
      ids->push_back(static_cast<uint8_t>(id));
    } else if (status.error != ServoError::kTimeout && status.error != ServoError::kBadAnswer) {
      return fail(status.error, "scan stopped at id " + std::to_string(id) + ": " + status.message);
    }
  }
  std::string list;
  for (uint8_t id : *ids) list += (list.empty() ? "" : ", ") + std::to_string(id);
  return ok(std::to_string(ids->size()) + " of " + std::to_string(last_id - first_id + 1) +
            " ids answered PING" + (list.empty() ? "" : ": " + list));
}

// Parameters: READ_DATA / WRITE_DATA with their checks and read-back, READ_BATCH_DATA and
// RESET_USER_DATA.

ServoStatus ServoBusClient::readParamLocked(uint8_t id, const ParamInfo& param,
                                            ServoParamValue* value) {
  // The answer's size follows from the parameter's type, not from the command alone.
  Expectation expect(Command::kReadData, id, kReadDataHeader + typeSize(param.type));
  expect.data_id = param.data_id;
  Packet answer;
  const ServoStatus status =
      transactions_.exchangeLocked(encodeReadData(id, param.data_id), expect, &answer);
  if (!status.ok()) return status;
  const protocol::Decoded<int64_t> raw = decodeReadDataAnswer(answer, param);
  if (!raw) {
    return fail(ServoError::kBadAnswer,
                servoName(id) + " sent an unreadable value for " + quoted(param.name));
  }
  *value = toParamValue(param, *raw);
  return ok(servoName(id) + " " + quoted(param.name) + " = " + valueText(*value));
}

ServoStatus ServoBusClient::readParam(uint8_t id, std::string_view param_name,
                                      ServoParamValue* value, BusPriority priority) {
  const ParamInfo* param = findParam(param_name);
  if (param == nullptr) {
    return fail(ServoError::kUnknownParam,
                "unknown servo parameter " + quoted(param_name) +
                    " (use a name such as 'voltage' or a data_id such as '51')");
  }
  if (auto rejection = rejectBroadcast(id, Command::kReadData)) return *rejection;
  if (priority == BusPriority::kBackground) {
    if (!transactions_.takeBus(BusPriority::kBackground)) {
      return fail(ServoError::kPreempted, servoName(id) + "'s health poll gave way to a stop");
    }
    std::lock_guard<BusMutex> bus(transactions_.busMutex(), std::adopt_lock);
    return readParamLocked(id, *param, value);
  }
  std::lock_guard<BusMutex> bus(transactions_.busMutex());
  return readParamLocked(id, *param, value);
}

ServoStatus ServoBusClient::checkIdFreeLocked(uint8_t id, uint8_t new_id) {
  // Two servos with one id can no longer be told apart: make sure the new id is free.
  const ServoStatus probe = pingLocked(new_id);
  if (probe.ok()) {
    return fail(ServoError::kIdInUse, "servo_id change of " + servoName(id) +
                                          " refused: a servo already answers at id " +
                                          std::to_string(new_id));
  }
  if (probe.error != ServoError::kTimeout) return probe;
  return ok("");
}

ServoStatus ServoBusClient::writeParam(uint8_t id, std::string_view param_name, int64_t value) {
  const ParamInfo* param = findParam(param_name);
  if (param == nullptr) {
    return fail(ServoError::kUnknownParam,
                "unknown servo parameter " + quoted(param_name) +
                    " (use a name such as 'soft_start_time' or a data_id such as '50')");
  }
  if (auto rejection = rejectBroadcast(id, Command::kWriteData)) return *rejection;
  const WriteCheck check =
      checkWrite(*param, value, transactions_.options().allow_dangerous_writes);
  if (check != WriteCheck::kOk) return fromWriteCheck(check, *param, value);

  // One lock for the probe, the write and the read-back: no other call comes between them, but
  // each transaction hands the bus to a stop first (transact), so a stop waits for one attempt.
  std::lock_guard<BusMutex> bus(transactions_.busMutex());
  const bool id_change = param->data_id == dataId(ServoDataId::kServoId) && value != id;
  const uint8_t new_id = static_cast<uint8_t>(value);
  if (id_change) {
    const ServoStatus free = checkIdFreeLocked(id, new_id);
    if (!free.ok()) return free;
  }

  Expectation expect(Command::kWriteData, id);
  if (id_change) expect.alt_id = new_id;  // the answer may already come from the new address
  expect.data_id = param->data_id;
  Packet answer;
  const ServoStatus status =
      transactions_.exchangeLocked(encodeWriteData(id, *param, value), expect, &answer);
  if (!status.ok()) return status;
  const std::string assignment = quoted(param->name) + " = " + std::to_string(value);
  if (refused(answer)) {
    return fail(ServoError::kRefused,
                servoName(id) + " refused to write " + assignment + " (result 0)");
  }
  if (param->data_id == kBaudrateParam) {
    return ok(servoName(id) + " accepted " + assignment +
              "; not read back because the new baud rate takes effect at once");
  }

  const uint8_t read_id = id_change ? new_id : id;
  ServoParamValue read_back;
  const ServoStatus read_status = readParamLocked(read_id, *param, &read_back);
  if (!read_status.ok()) {
    return fail(read_status.error, servoName(id) + " accepted " + assignment +
                                       " but the read-back failed: " + read_status.message);
  }
  if (read_back.value != value) {
    return fail(ServoError::kReadBackMismatch, "wrote " + assignment + " to " + servoName(id) +
                                                   " but it reads back " +
                                                   std::to_string(read_back.value));
  }
  if (id_change) {
    return ok(servoName(id) + " is now " + servoName(new_id) + " (read back at the new id)");
  }
  return ok(servoName(id) + " " + quoted(param->name) + " = " + valueText(read_back) +
            " (written and read back)");
}

ServoStatus ServoBusClient::readAll(uint8_t id, std::vector<ServoParamValue>* values) {
  if (auto rejection = rejectBroadcast(id, Command::kReadBatchData)) return *rejection;
  Packet answer;
  const ServoStatus status = transactions_.exchange(
      encodeReadBatchData(id), Expectation(Command::kReadBatchData, id), &answer);
  if (!status.ok()) return status;

  // The exchange checked the answer's size against the command table, so the block is whole.
  const auto block = decodeUserBlock(answer);
  if (!block) {
    return fail(ServoError::kBadAnswer, servoName(id) + " sent a user block of the wrong size");
  }
  std::vector<ServoParamValue> result;
  for (const auto& [param, raw] : unpackUserBlock(*block)) {
    result.push_back(toParamValue(*param, raw));
  }
  const std::size_t count = result.size();
  *values = std::move(result);
  return ok("read " + std::to_string(count) + " parameters of " + servoName(id));
}

ServoStatus ServoBusClient::resetUserData(uint8_t id) {
  if (auto rejection = rejectBroadcast(id, Command::kResetUserData)) return *rejection;
  if (!transactions_.options().allow_dangerous_writes) {
    return fail(ServoError::kDangerous,
                "reset_user_data restores the factory id and baud rate and can make the servo "
                "unreachable; refused because dangerous writes are not allowed");
  }
  Expectation expect(Command::kResetUserData, id);
  expect.alt_id = kServoIdAfterReset;  // the reset moves the servo to id 0 and it may answer there
  // One lock for every attempt and PING: a stop still goes first after the one in flight.
  std::lock_guard<BusMutex> bus(transactions_.busMutex());
  ServoStatus last;
  const ServoBusOptions options = transactions_.options();  // the same for every attempt
  for (int attempt = 1; attempt <= options.retries + 1; ++attempt) {
    Packet answer;
    // One attempt at a time: a re-sent reset would go to an id the servo may have left already.
    last = transactions_.transact(encodeResetUserData(id), expect, options.timeout, 1, &answer);
    if (last.ok()) {
      if (refused(answer)) {
        return fail(ServoError::kRefused, servoName(id) + " refused RESET_USER_DATA (result 0)");
      }
      return ok(servoName(id) +
                " reset its user data to the factory defaults; it now answers at "
                "id 0 (answer from id " +
                std::to_string(answer.id()) + ")");
    }
    if (last.error != ServoError::kTimeout) return last;
    // No answer: the servo may have reset and moved to id 0 without answering. (For a servo at
    // id 0 already a PING proves nothing: the reset is re-sent instead.)
    if (id != kServoIdAfterReset && pingOnceLocked(kServoIdAfterReset).ok()) {
      return ok(servoName(id) +
                " reset its user data to the factory defaults; it gave no answer "
                "but now answers PING at id 0");
    }
  }
  return fail(ServoError::kTimeout, servoName(id) +
                                        " did not answer RESET_USER_DATA and no servo "
                                        "answers PING at id 0 (" +
                                        last.message + ")");
}

// Motions: servo/move (CMD 8, 11..15), ROTATE, SPIN and DAMPING.

ServoStatus ServoBusClient::move(const MoveRequest& request, BusPriority priority,
                                 std::optional<core::MotionGate::Generation> accepted) {
  MoveCommand command;
  const ServoStatus checked = toMoveCommand(request, &command);
  if (!checked.ok()) return checked;
  const std::vector<uint8_t> frame = encodeMove(command);
  if (!transactions_.takeBus(priority)) return gaveWayToAStop(command.cmd, request.id);
  std::lock_guard<BusMutex> bus(transactions_.busMutex(), std::adopt_lock);
  return transactions_.sendCommand(frame, command.cmd, request.id, FrameGate::kMotion, accepted);
}

ServoStatus ServoBusClient::rotate(const RotateRequest& request,
                                   std::optional<core::MotionGate::Generation> accepted) {
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
  const std::vector<uint8_t> frame = encodeRotate(request.id, static_cast<int16_t>(decidegrees),
                                                  request.interval_ms, request.power_mw);
  return sendMotion(frame, Command::kRotate, request.id, request.wait,
                    std::chrono::milliseconds(request.interval_ms), FrameGate::kMotion,
                    request.priority, accepted);
}

ServoStatus ServoBusClient::spin(const SpinRequest& request,
                                 std::optional<core::MotionGate::Generation> accepted) {
  if (request.mode > kMaxSpinMode) {
    return fail(ServoError::kInvalidArgument,
                "spin mode " + std::to_string(request.mode) +
                    " is out of range 0..3 (0 stop, 1 continuous, 2 turns, 3 milliseconds)");
  }
  const auto mode = static_cast<SpinMode>(request.mode);
  std::chrono::milliseconds motion_time{0};
  if (request.wait) {
    if (auto rejection = rejectBroadcast(request.id, Command::kSpin)) return *rejection;
    double expected_ms = 0.0;
    if (mode == SpinMode::kDurationMs) {
      expected_ms = request.value;
    } else if (mode == SpinMode::kTurns && request.speed_dps > 0) {
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
      encodeSpin(request.id, request.clockwise, mode, request.speed_dps, request.value);
  // A SPIN stop is what the e-stop itself sends: never held back, and urgent work.
  const bool stop = mode == SpinMode::kStop;
  return sendMotion(frame, Command::kSpin, request.id, request.wait, motion_time,
                    stop ? FrameGate::kSafetyAction : FrameGate::kMotion,
                    stop ? BusPriority::kStop : request.priority, accepted);
}

ServoStatus ServoBusClient::damping(uint8_t id, uint16_t power_mw, bool wait, FrameGate gate) {
  if (wait) {
    if (auto rejection = rejectBroadcast(id, Command::kDamping)) return *rejection;
  }
  const std::vector<uint8_t> frame = encodeDamping(id, power_mw);
  // Torque off moves nothing: it goes out as a stop does.
  return sendMotion(frame, Command::kDamping, id, wait, std::chrono::milliseconds(0), gate,
                    BusPriority::kStop, std::nullopt);
}

ServoStatus ServoBusClient::sendMotion(const std::vector<uint8_t>& request, Command cmd, uint8_t id,
                                       bool wait, std::chrono::milliseconds motion_time,
                                       FrameGate gate, BusPriority priority,
                                       std::optional<core::MotionGate::Generation> accepted) {
  if (!transactions_.takeBus(priority)) return gaveWayToAStop(cmd, id);
  std::lock_guard<BusMutex> bus(transactions_.busMutex(), std::adopt_lock);
  if (!wait) return transactions_.sendCommand(request, cmd, id, gate, accepted);
  Packet answer;
  // A motion is never re-sent: with response_switch = 1 commands are queued, so a second copy
  // would run the motion twice.
  ServoStatus status = transactions_.transact(request, Expectation(cmd, id),
                                              motion_time + transactions_.options().timeout, 1,
                                              &answer, gate, false, nullptr, accepted);
  if (!status.ok()) {
    if (status.error == ServoError::kTimeout) {
      status.message += "; the servo answers motion commands only when response_switch is 1";
    }
    return status;
  }
  if (refused(answer)) {
    return fail(ServoError::kRefused,
                servoName(id) + " reported " + commandName(cmd) + " failed (result 0)");
  }
  return ok(std::string(commandName(cmd)) + " completed by " + servoName(id) + ", " +
            status.message);
}

}  // namespace serial_robot_driver::devices::servo_bus
