#include "serial_robot_driver/device/servo_bus_client.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "serial_robot_driver/protocol/byte_order.h"

namespace serial_robot_driver::device {

namespace servo = protocol::servo;
using servo::Command;
using servo::ParamInfo;

namespace {

constexpr uint8_t kServoIdParam = servo::dataId(servo::ServoDataId::kServoId);
constexpr uint8_t kBaudrateParam = servo::dataId(servo::ServoDataId::kBaudrate);
constexpr uint8_t kResultFailed = 0;
constexpr double kDecidegreesPerDegree = 10.0;
constexpr uint8_t kMaxSpinMode = 3;
constexpr double kDegreesPerTurn = 360.0;

// Answer content sizes (docs/protocols.md, section 3, response column).
constexpr std::size_t kIdOnlyAnswer = 1;        // id
constexpr std::size_t kResultAnswer = 2;        // id, result
constexpr std::size_t kWriteDataAnswer = 3;     // id, data_id, result
constexpr std::size_t kReadAngleAnswer = 3;     // id, angle (i16)
constexpr std::size_t kReadDataHeader = 2;      // id, data_id, then the value
constexpr std::size_t kBatchAnswer = 1 + servo::kUserBlockSize;

// servo/move limits (vendor SDK and datasheet).
constexpr double kMaxSingleTurnDeg = 180.0;
constexpr double kMaxMultiTurnDeg = 368640.0;  // 1024 turns
constexpr double kMaxVelocityDps = 750.0;
constexpr double kMinVelocityDps = 0.1;  // the wire unit; anything less is sent as 0
constexpr uint16_t kMinRampMs = 20;      // the firmware's shortest ramp
constexpr uint32_t kMaxMultiTurnIntervalMs = 4096000;
constexpr uint8_t kDefaultServoId = 0;  // what RESET_USER_DATA sets the id to

std::string formatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", value);
  return text;
}

const char* commandName(Command cmd) {
  switch (cmd) {
    case Command::kPing:
      return "PING";
    case Command::kResetUserData:
      return "RESET_USER_DATA";
    case Command::kReadData:
      return "READ_DATA";
    case Command::kWriteData:
      return "WRITE_DATA";
    case Command::kReadBatchData:
      return "READ_BATCH_DATA";
    case Command::kWriteBatchData:
      return "WRITE_BATCH_DATA";
    case Command::kSpin:
      return "SPIN";
    case Command::kRotate:
      return "ROTATE";
    case Command::kDamping:
      return "DAMPING";
    case Command::kReadAngle:
      return "READ_ANGLE";
    case Command::kMoveByInterval:
      return "MOVE_BY_INTERVAL (CMD 11)";
    case Command::kMoveByVelocity:
      return "MOVE_BY_VELOCITY (CMD 12)";
    case Command::kMultiTurnMove:
      return "MULTI_TURN_MOVE (CMD 13)";
    case Command::kMultiTurnMoveByInterval:
      return "MULTI_TURN_MOVE_BY_INTERVAL (CMD 14)";
    case Command::kMultiTurnMoveByVelocity:
      return "MULTI_TURN_MOVE_BY_VELOCITY (CMD 15)";
    case Command::kReadMultiTurnAngle:
      return "READ_MULTI_TURN_ANGLE (CMD 16)";
  }
  return "UNKNOWN";
}

std::string servoName(uint8_t id) {
  if (id == servo::kBroadcastId) return "all servos (broadcast id 255)";
  return "servo " + std::to_string(id);
}

/// Quotes a name for a message; a caller's absurdly long string is cut, not echoed in full.
std::string quoted(std::string_view name) {
  constexpr std::size_t kMaxShown = 40;
  if (name.size() <= kMaxShown) return "'" + std::string(name) + "'";
  return "'" + std::string(name.substr(0, kMaxShown)) + "...' (" + std::to_string(name.size()) +
         " characters)";
}

std::string formatMs(double ms) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f ms", ms);
  return text;
}

std::string attemptsText(int attempts) {
  return std::to_string(attempts) + (attempts == 1 ? " attempt" : " attempts");
}

ServoStatus ok(std::string message) { return {ServoError::kOk, std::move(message)}; }
ServoStatus fail(ServoError error, std::string message) { return {error, std::move(message)}; }

ServoStatus notConnected() {
  return fail(ServoError::kNotConnected, "servo bus port is not connected");
}

// Commands that need one servo's answer cannot go to the broadcast id: every servo would answer
// at once and the answers would collide on the bus.
std::optional<ServoStatus> rejectBroadcast(uint8_t id, Command cmd) {
  if (id != servo::kBroadcastId) return std::nullopt;
  return fail(ServoError::kInvalidArgument,
              std::string("id 255 is the broadcast address; ") + commandName(cmd) +
                  " needs the answer of one servo (ids 0..254)");
}

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

double toMs(Clock::duration duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

}  // namespace

const char* toString(ServoError error) {
  switch (error) {
    case ServoError::kOk:
      return "ok";
    case ServoError::kInvalidArgument:
      return "invalid argument";
    case ServoError::kUnknownParam:
      return "unknown parameter";
    case ServoError::kReadOnly:
      return "read-only parameter";
    case ServoError::kOutOfRange:
      return "value out of range";
    case ServoError::kDangerous:
      return "dangerous write refused";
    case ServoError::kNotConnected:
      return "port not connected";
    case ServoError::kIdInUse:
      return "servo id in use";
    case ServoError::kTimeout:
      return "timeout";
    case ServoError::kBadAnswer:
      return "malformed answer";
    case ServoError::kRefused:
      return "refused by the servo";
    case ServoError::kReadBackMismatch:
      return "read-back mismatch";
    case ServoError::kShutdown:
      return "shutting down";
  }
  return "unknown";
}

void BusMutex::lock() {
  std::unique_lock<std::mutex> lock(mutex_);
  ++waiting_;
  released_.wait(lock, [this] { return !held_; });
  --waiting_;
  held_ = true;
}

void BusMutex::lockBackground() {
  std::unique_lock<std::mutex> lock(mutex_);
  released_.wait(lock, [this] { return !held_ && waiting_ == 0; });
  held_ = true;
}

int BusMutex::foregroundWaiting() {
  std::lock_guard<std::mutex> lock(mutex_);
  return waiting_;
}

void BusMutex::unlock() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    held_ = false;
  }
  released_.notify_all();
}

ServoBusClient::ServoBusClient(ServoBusOptions options, FrameWriter writer)
    : options_(std::move(options)), writer_(std::move(writer)) {}

ServoBusStats ServoBusClient::stats() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return stats_;
}

void ServoBusClient::shutdown() {
  std::lock_guard<std::mutex> lock(state_mutex_);
  stopping_ = true;
  answer_cv_.notify_all();
}

void ServoBusClient::onLinkDown() {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (pending_.active) {
    link_lost_ = true;
    answer_cv_.notify_all();
  }
}

bool ServoBusClient::matches(const servo::Packet& packet) const {
  const Expectation& expect = pending_.expect;
  if (packet.cmd != static_cast<uint8_t>(expect.cmd) || packet.content_size == 0) return false;
  const uint8_t id = packet.id();
  if (id != expect.id && !(expect.alt_id && id == *expect.alt_id)) return false;
  // An answer about another data_id is a late answer to an earlier request, not garbage.
  if (expect.data_id && (packet.content_size < 2 || packet.content[1] != *expect.data_id)) {
    return false;
  }
  return true;
}

void ServoBusClient::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                             Clock::time_point arrival) {
  if (family == protocol::FrameFamily::kServoRequest) {
    // On a half-duplex adapter our own request comes back: recognise it, skip it.
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (!last_request_.empty() && size == last_request_.size() &&
        std::equal(data, data + size, last_request_.begin())) {
      ++stats_.echoes;
    } else {
      ++stats_.mismatched;  // another host's request: not ours to answer or wait for
    }
    return;
  }
  if (family != protocol::FrameFamily::kServoResponse) return;  // another device on this port

  const protocol::Decoded<servo::Packet> packet = servo::decodeResponse(data, size);
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (!packet.ok()) {
    ++stats_.garbled;
    return;
  }
  if (!pending_.active || pending_.answered || pending_.garbled || !matches(*packet)) {
    ++stats_.mismatched;
    return;
  }
  if (packet->content_size != pending_.expect.content_size) {
    ++stats_.garbled;
    pending_.garbled = true;
  } else {
    pending_.answered = true;
  }
  pending_.answer = *packet;
  pending_.arrival = arrival;
  answer_cv_.notify_all();
}

ServoStatus ServoBusClient::transact(const std::vector<uint8_t>& request, const Expectation& expect,
                                     std::chrono::milliseconds timeout, int attempts,
                                     servo::Packet* answer) {
  bool any_garbled = false;
  std::size_t garbled_size = 0;
  for (int attempt = 1; attempt <= attempts; ++attempt) {
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      if (stopping_) return fail(ServoError::kShutdown, "servo bus client is shutting down");
      pending_ = Pending{};
      pending_.active = true;
      pending_.expect = expect;
      last_request_ = request;
      link_lost_ = false;
    }
    const Clock::time_point sent_at = Clock::now();
    if (!writer_(request)) {
      std::lock_guard<std::mutex> lock(state_mutex_);
      pending_.active = false;
      return notConnected();
    }

    std::unique_lock<std::mutex> lock(state_mutex_);
    if (attempt == 1) {
      ++stats_.transactions;
    } else {
      ++stats_.retries;
    }
    answer_cv_.wait_until(lock, sent_at + timeout, [this] {
      return pending_.answered || pending_.garbled || link_lost_ || stopping_;
    });
    pending_.active = false;

    if (pending_.answered) {
      const double latency_ms = toMs(pending_.arrival - sent_at);
      stats_.last_latency_ms = latency_ms;
      stats_.max_latency_ms = std::max(stats_.max_latency_ms, latency_ms);
      *answer = pending_.answer;
      return ok("answered in " + formatMs(latency_ms));
    }
    if (link_lost_) {
      return fail(ServoError::kNotConnected,
                  "servo bus port was lost while waiting for " + servoName(expect.id) + "'s " +
                      commandName(expect.cmd) + " answer");
    }
    if (stopping_) return fail(ServoError::kShutdown, "servo bus client is shutting down");
    if (pending_.garbled) {
      any_garbled = true;
      garbled_size = pending_.answer.content_size;
    }
  }

  if (any_garbled) {
    return fail(ServoError::kBadAnswer,
                servoName(expect.id) + " sent a malformed " + commandName(expect.cmd) +
                    " answer (" + std::to_string(garbled_size) + " content bytes, expected " +
                    std::to_string(expect.content_size) + ")");
  }
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.timeouts;
  }
  return fail(ServoError::kTimeout, servoName(expect.id) + " did not answer " +
                                        commandName(expect.cmd) + " within " +
                                        std::to_string(timeout.count()) + " ms (" +
                                        attemptsText(attempts) + ")");
}

ServoStatus ServoBusClient::exchangeLocked(const std::vector<uint8_t>& request,
                                           const Expectation& expect, servo::Packet* answer) {
  return transact(request, expect, options_.timeout, options_.retries + 1, answer);
}

ServoStatus ServoBusClient::exchange(const std::vector<uint8_t>& request, const Expectation& expect,
                                     servo::Packet* answer) {
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return exchangeLocked(request, expect, answer);
}

ServoStatus ServoBusClient::sendCommand(const std::vector<uint8_t>& request, Command cmd,
                                        uint8_t id) {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (stopping_) return fail(ServoError::kShutdown, "servo bus client is shutting down");
    last_request_ = request;
  }
  if (!writer_(request)) return notConnected();
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.commands;
  }
  return ok(std::string(commandName(cmd)) + " sent to " + servoName(id) +
            " (not waiting for completion)");
}

ServoStatus ServoBusClient::sendMotion(const std::vector<uint8_t>& request, Command cmd, uint8_t id,
                                       bool wait, std::chrono::milliseconds motion_time) {
  if (!wait) return sendCommand(request, cmd, id);
  servo::Packet answer;
  // A motion is never re-sent: with response_switch = 1 commands are queued, so a second copy
  // would run the motion twice.
  ServoStatus status = transact(request, Expectation(cmd, id, kResultAnswer),
                                motion_time + options_.timeout, 1, &answer);
  if (!status.ok()) {
    if (status.error == ServoError::kTimeout) {
      status.message += "; the servo answers motion commands only when response_switch is 1";
    }
    return status;
  }
  if (answer.content[1] == kResultFailed) {
    return fail(ServoError::kRefused,
                servoName(id) + " reported " + commandName(cmd) + " failed (result 0)");
  }
  return ok(std::string(commandName(cmd)) + " completed by " + servoName(id) + ", " +
            status.message);
}

ServoStatus ServoBusClient::pingLocked(uint8_t id) {
  servo::Packet answer;
  const ServoStatus status = exchangeLocked(
      servo::encodePing(id), Expectation(Command::kPing, id, kIdOnlyAnswer), &answer);
  if (!status.ok()) return status;
  return ok(servoName(id) + " is online (" + status.message + ")");
}

ServoStatus ServoBusClient::ping(uint8_t id) {
  if (auto rejection = rejectBroadcast(id, Command::kPing)) return *rejection;
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return pingLocked(id);
}

ServoStatus ServoBusClient::readParamLocked(uint8_t id, const ParamInfo& param,
                                            ServoParamValue* value) {
  Expectation expect(Command::kReadData, id, kReadDataHeader + servo::typeSize(param.type));
  expect.data_id = param.data_id;
  servo::Packet answer;
  const ServoStatus status =
      exchangeLocked(servo::encodeReadData(id, param.data_id), expect, &answer);
  if (!status.ok()) return status;
  const std::optional<int64_t> raw = servo::readValue(
      param, answer.content.data() + kReadDataHeader, answer.content_size - kReadDataHeader);
  if (!raw) {
    return fail(ServoError::kBadAnswer, servoName(id) + " sent an unreadable value for " +
                                            quoted(param.name));
  }
  *value = toParamValue(param, *raw);
  return ok(servoName(id) + " " + quoted(param.name) + " = " + valueText(*value));
}

ServoStatus ServoBusClient::readParam(uint8_t id, std::string_view param_name,
                                      ServoParamValue* value) {
  const ParamInfo* param = servo::findParam(param_name);
  if (param == nullptr) {
    return fail(ServoError::kUnknownParam,
                "unknown servo parameter " + quoted(param_name) +
                    " (use a name such as 'voltage' or a data_id such as '51')");
  }
  if (auto rejection = rejectBroadcast(id, Command::kReadData)) return *rejection;
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

  Expectation expect(Command::kWriteData, id, kWriteDataAnswer);
  if (id_change) expect.alt_id = new_id;  // the answer may already come from the new address
  expect.data_id = param->data_id;
  servo::Packet answer;
  const ServoStatus status =
      exchangeLocked(servo::encodeWriteData(id, *param, value), expect, &answer);
  if (!status.ok()) return status;
  const std::string assignment = quoted(param->name) + " = " + std::to_string(value);
  if (answer.content[2] == kResultFailed) {
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
    return fail(ServoError::kReadBackMismatch,
                "wrote " + assignment + " to " + servoName(id) + " but it reads back " +
                    std::to_string(read_back.value));
  }
  if (id_change) {
    return ok(servoName(id) + " is now " + servoName(new_id) + " (read back at the new id)");
  }
  return ok(servoName(id) + " " + quoted(param->name) + " = " + valueText(read_back) +
            " (written and read back)");
}

ServoStatus ServoBusClient::readAngle(uint8_t id, double* angle_deg, Clock::time_point* arrival) {
  if (auto rejection = rejectBroadcast(id, Command::kReadAngle)) return *rejection;
  servo::Packet answer;
  Clock::time_point answered_at;
  ServoStatus status;
  {
    std::lock_guard<BusMutex> bus(bus_mutex_);
    status = exchangeLocked(servo::encodeReadAngle(id),
                            Expectation(Command::kReadAngle, id, kReadAngleAnswer), &answer);
    std::lock_guard<std::mutex> lock(state_mutex_);
    answered_at = pending_.arrival;
  }
  if (!status.ok()) return status;
  if (arrival != nullptr) *arrival = answered_at;
  const int16_t decidegrees = protocol::readLE16Signed(&answer.content[1]);
  *angle_deg = decidegrees / kDecidegreesPerDegree;
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f deg", *angle_deg);
  return ok(servoName(id) + " is at " + text);
}

ServoStatus ServoBusClient::pollAngle(uint8_t id, double* angle_deg, Clock::time_point* arrival) {
  if (auto rejection = rejectBroadcast(id, Command::kReadAngle)) return *rejection;
  servo::Packet answer;
  Clock::time_point answered_at;
  ServoStatus status;
  bus_mutex_.lockBackground();
  {
    std::lock_guard<BusMutex> bus(bus_mutex_, std::adopt_lock);
    status =
        transact(servo::encodeReadAngle(id), Expectation(Command::kReadAngle, id, kReadAngleAnswer),
                 options_.timeout, 1, &answer);
    std::lock_guard<std::mutex> lock(state_mutex_);
    answered_at = pending_.arrival;
  }
  if (!status.ok()) return status;
  *arrival = answered_at;
  *angle_deg = protocol::readLE16Signed(&answer.content[1]) / kDecidegreesPerDegree;
  return status;
}

ServoStatus ServoBusClient::readMultiTurnAngle(uint8_t id, MultiTurnReading* reading) {
  if (auto rejection = rejectBroadcast(id, Command::kReadMultiTurnAngle)) return *rejection;
  servo::Packet answer;
  const ServoStatus status = exchange(
      servo::encodeReadMultiTurnAngle(id),
      Expectation(Command::kReadMultiTurnAngle, id, servo::kMultiTurnAngleAnswerSize), &answer);
  if (!status.ok()) return status;
  const protocol::Decoded<servo::MultiTurnAngle> decoded =
      servo::decodeMultiTurnAngle(answer.content.data(), answer.content_size);
  if (!decoded) {
    return fail(ServoError::kBadAnswer, servoName(id) + " sent an unreadable multi-turn angle");
  }
  reading->angle_deg = decoded->angle_decidegrees / kDecidegreesPerDegree;
  reading->turns = decoded->turns;
  char text[64];
  std::snprintf(text, sizeof(text), "%.1f deg (%d turns)", reading->angle_deg, reading->turns);
  return ok(servoName(id) + " is at " + text);
}

ServoStatus ServoBusClient::move(const MoveRequest& request) {
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
  std::vector<uint8_t> frame;
  Command cmd = Command::kRotate;
  if (by_velocity) {
    cmd = request.multi_turn ? Command::kMultiTurnMoveByVelocity : Command::kMoveByVelocity;
    frame =
        request.multi_turn
            ? servo::encodeMultiTurnMoveByVelocity(request.id, angle, velocity, ramps)
            : servo::encodeMoveByVelocity(request.id, static_cast<int16_t>(angle), velocity, ramps);
  } else if (with_ramps) {
    cmd = request.multi_turn ? Command::kMultiTurnMoveByInterval : Command::kMoveByInterval;
    frame =
        request.multi_turn
            ? servo::encodeMultiTurnMoveByInterval(request.id, angle, request.interval_ms, ramps)
            : servo::encodeMoveByInterval(request.id, static_cast<int16_t>(angle),
                                          static_cast<uint16_t>(request.interval_ms), ramps);
  } else if (request.multi_turn) {
    cmd = Command::kMultiTurnMove;
    frame = servo::encodeMultiTurnMove(request.id, angle, request.interval_ms, request.power_mw);
  } else {
    frame = servo::encodeRotate(request.id, static_cast<int16_t>(angle),
                                static_cast<uint16_t>(request.interval_ms), request.power_mw);
  }
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return sendCommand(frame, cmd, request.id);
}

ServoStatus ServoBusClient::pingOnceLocked(uint8_t id) {
  servo::Packet answer;
  return transact(servo::encodePing(id), Expectation(Command::kPing, id, kIdOnlyAnswer),
                  options_.timeout, 1, &answer);
}

ServoStatus ServoBusClient::scan(uint8_t first_id, uint8_t last_id, std::vector<uint8_t>* ids) {
  if (first_id > last_id) {
    return fail(ServoError::kInvalidArgument, "first_id " + std::to_string(first_id) +
                                                  " is above last_id " + std::to_string(last_id));
  }
  if (last_id == servo::kBroadcastId) {
    return fail(ServoError::kInvalidArgument,
                "id 255 is the broadcast address and cannot be scanned (ids 0..254)");
  }
  ids->clear();
  for (int id = first_id; id <= last_id; ++id) {
    // The bus is taken per id: a service call or a poll waits for one PING at most.
    std::lock_guard<BusMutex> bus(bus_mutex_);
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
  const std::vector<uint8_t> frame =
      servo::encodeRotate(request.id, static_cast<int16_t>(decidegrees), request.interval_ms,
                          request.power_mw);
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return sendMotion(frame, Command::kRotate, request.id, request.wait,
                    std::chrono::milliseconds(request.interval_ms));
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
  const std::vector<uint8_t> frame = servo::encodeSpin(request.id, request.clockwise, mode,
                                                       request.speed_dps, request.value);
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return sendMotion(frame, Command::kSpin, request.id, request.wait, motion_time);
}

ServoStatus ServoBusClient::damping(uint8_t id, uint16_t power_mw, bool wait) {
  if (wait) {
    if (auto rejection = rejectBroadcast(id, Command::kDamping)) return *rejection;
  }
  const std::vector<uint8_t> frame = servo::encodeDamping(id, power_mw);
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return sendMotion(frame, Command::kDamping, id, wait, std::chrono::milliseconds(0));
}

ServoStatus ServoBusClient::readAll(uint8_t id, std::vector<ServoParamValue>* values) {
  if (auto rejection = rejectBroadcast(id, Command::kReadBatchData)) return *rejection;
  servo::Packet answer;
  const ServoStatus status =
      exchange(servo::encodeReadBatchData(id),
               Expectation(Command::kReadBatchData, id, kBatchAnswer), &answer);
  if (!status.ok()) return status;

  const uint8_t* block = answer.content.data() + 1;
  std::vector<ServoParamValue> result;
  for (const ParamInfo& param : servo::paramTable()) {
    const std::optional<std::size_t> offset = servo::userBlockOffset(param);
    if (!offset) continue;  // read-only parameters are not in the user block
    const std::size_t size = servo::typeSize(param.type);
    const std::optional<int64_t> raw =
        *offset + size <= servo::kUserBlockSize ? servo::readValue(param, block + *offset, size)
                                                : std::nullopt;
    if (!raw) {
      return fail(ServoError::kBadAnswer, servoName(id) + " sent a user block without " +
                                              quoted(param.name));
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
  Expectation expect(Command::kResetUserData, id, kResultAnswer);
  expect.alt_id = kDefaultServoId;  // the reset moves the servo to id 0 and it may answer there
  std::lock_guard<BusMutex> bus(bus_mutex_);
  ServoStatus last;
  for (int attempt = 1; attempt <= options_.retries + 1; ++attempt) {
    servo::Packet answer;
    // One attempt at a time: a re-sent reset would go to an id the servo may have left already.
    last = transact(servo::encodeResetUserData(id), expect, options_.timeout, 1, &answer);
    if (last.ok()) {
      if (answer.content[1] == kResultFailed) {
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
