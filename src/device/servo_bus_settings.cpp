// ServoBusClient's parameter operations: READ_DATA / WRITE_DATA with their checks and read-back,
// READ_BATCH_DATA and RESET_USER_DATA.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/device/servo_bus_client.h"
#include "servo_bus_text.h"

namespace serial_robot_driver::device {

namespace servo = protocol::servo;
using servo::Command;
using servo::ParamInfo;
using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

namespace {

constexpr uint8_t kServoIdParam = servo::dataId(servo::ServoDataId::kServoId);
constexpr uint8_t kBaudrateParam = servo::dataId(servo::ServoDataId::kBaudrate);
constexpr std::size_t kReadDataHeader = 2;  // id, data_id, then the value
constexpr uint8_t kDefaultServoId = 0;      // what RESET_USER_DATA sets the id to

ServoStatus fromWriteCheck(servo::WriteCheck check, const ParamInfo& param, int64_t value) {
  ServoError error = ServoError::kInvalidArgument;
  switch (check) {
    case servo::WriteCheck::kOk:
      return ok("");
    case servo::WriteCheck::kReadOnly:
      error = ServoError::kReadOnly;
      break;
    case servo::WriteCheck::kOutOfRange:
      error = ServoError::kOutOfRange;
      break;
    case servo::WriteCheck::kDangerous:
      error = ServoError::kDangerous;
      break;
  }
  // The switch that arms dangerous writes is named by the caller's layer (a ROS parameter there).
  return fail(error, servo::describe(check, param, value));
}

ServoParamValue toParamValue(const ParamInfo& param, int64_t raw) {
  // The table's units are already engineering units (mV, mA, mW, degC, ms, 0.1deg): no scaling.
  return ServoParamValue{std::string(param.name), param.data_id, raw, std::string(param.unit)};
}

std::string valueText(const ServoParamValue& value) {
  std::string text = std::to_string(value.value);
  if (!value.unit.empty()) text += " " + value.unit;
  return text;
}

}  // namespace

ServoStatus ServoBusClient::readParamLocked(uint8_t id, const ParamInfo& param,
                                            ServoParamValue* value) {
  // The answer's size follows from the parameter's type, not from the command alone.
  Expectation expect(Command::kReadData, id, kReadDataHeader + servo::typeSize(param.type));
  expect.data_id = param.data_id;
  servo::Packet answer;
  const ServoStatus status =
      exchangeLocked(servo::encodeReadData(id, param.data_id), expect, &answer);
  if (!status.ok()) return status;
  const protocol::Decoded<int64_t> raw = servo::decodeReadDataAnswer(answer, param);
  if (!raw) {
    return fail(ServoError::kBadAnswer,
                servoName(id) + " sent an unreadable value for " + quoted(param.name));
  }
  *value = toParamValue(param, *raw);
  return ok(servoName(id) + " " + quoted(param.name) + " = " + valueText(*value));
}

ServoStatus ServoBusClient::readParam(uint8_t id, std::string_view param_name,
                                      ServoParamValue* value, BusPriority priority) {
  const ParamInfo* param = servo::findParam(param_name);
  if (param == nullptr) {
    return fail(ServoError::kUnknownParam,
                "unknown servo parameter " + quoted(param_name) +
                    " (use a name such as 'voltage' or a data_id such as '51')");
  }
  if (auto rejection = rejectBroadcast(id, Command::kReadData)) return *rejection;
  if (priority == BusPriority::kBackground) {
    if (!takeBus(BusPriority::kBackground)) {
      return fail(ServoError::kPreempted, servoName(id) + "'s health poll gave way to a stop");
    }
    std::lock_guard<BusMutex> bus(bus_mutex_, std::adopt_lock);
    return readParamLocked(id, *param, value);
  }
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return readParamLocked(id, *param, value);
}

ServoStatus ServoBusClient::writeParam(uint8_t id, std::string_view param_name, int64_t value) {
  const ParamInfo* param = servo::findParam(param_name);
  if (param == nullptr) {
    return fail(ServoError::kUnknownParam,
                "unknown servo parameter " + quoted(param_name) +
                    " (use a name such as 'soft_start_time' or a data_id such as '50')");
  }
  if (auto rejection = rejectBroadcast(id, Command::kWriteData)) return *rejection;
  const servo::WriteCheck check = servo::checkWrite(*param, value, options_.allow_dangerous_writes);
  if (check != servo::WriteCheck::kOk) return fromWriteCheck(check, *param, value);

  std::lock_guard<BusMutex> bus(bus_mutex_);
  const bool id_change = param->data_id == kServoIdParam && value != id;
  const uint8_t new_id = static_cast<uint8_t>(value);
  if (id_change) {
    // Two servos with one id can no longer be told apart: make sure the new id is free.
    const ServoStatus probe = pingLocked(new_id);
    if (probe.ok()) {
      return fail(ServoError::kIdInUse, "servo_id change of " + servoName(id) +
                                            " refused: a servo already answers at id " +
                                            std::to_string(new_id));
    }
    if (probe.error != ServoError::kTimeout) return probe;
  }

  Expectation expect(Command::kWriteData, id);
  if (id_change) expect.alt_id = new_id;  // the answer may already come from the new address
  expect.data_id = param->data_id;
  servo::Packet answer;
  const ServoStatus status =
      exchangeLocked(servo::encodeWriteData(id, *param, value), expect, &answer);
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
  servo::Packet answer;
  const ServoStatus status =
      exchange(servo::encodeReadBatchData(id), Expectation(Command::kReadBatchData, id), &answer);
  if (!status.ok()) return status;

  const uint8_t* block = answer.content.data() + 1;
  std::vector<ServoParamValue> result;
  for (const ParamInfo& param : servo::paramTable()) {
    const std::optional<std::size_t> offset = servo::userBlockOffset(param);
    if (!offset) continue;  // read-only parameters are not in the user block
    const std::size_t size = servo::typeSize(param.type);
    const std::optional<int64_t> raw = *offset + size <= servo::kUserBlockSize
                                           ? servo::readValue(param, block + *offset, size)
                                           : std::nullopt;
    if (!raw) {
      return fail(ServoError::kBadAnswer,
                  servoName(id) + " sent a user block without " + quoted(param.name));
    }
    result.push_back(toParamValue(param, *raw));
  }
  const std::size_t count = result.size();
  *values = std::move(result);
  return ok("read " + std::to_string(count) + " parameters of " + servoName(id));
}

ServoStatus ServoBusClient::resetUserData(uint8_t id) {
  if (auto rejection = rejectBroadcast(id, Command::kResetUserData)) return *rejection;
  if (!options_.allow_dangerous_writes) {
    return fail(ServoError::kDangerous,
                "reset_user_data restores the factory id and baud rate and can make the servo "
                "unreachable; refused because dangerous writes are not allowed");
  }
  Expectation expect(Command::kResetUserData, id);
  expect.alt_id = kDefaultServoId;  // the reset moves the servo to id 0 and it may answer there
  std::lock_guard<BusMutex> bus(bus_mutex_);
  ServoStatus last;
  const ServoBusOptions options = this->options();  // the same for every attempt
  for (int attempt = 1; attempt <= options.retries + 1; ++attempt) {
    servo::Packet answer;
    // One attempt at a time: a re-sent reset would go to an id the servo may have left already.
    last = transact(servo::encodeResetUserData(id), expect, options.timeout, 1, &answer);
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
    if (id != kDefaultServoId && pingOnceLocked(kDefaultServoId).ok()) {
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

}  // namespace serial_robot_driver::device
