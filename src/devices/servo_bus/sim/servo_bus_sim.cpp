#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "serial_robot_driver/devices/servo_bus/servo_commands.h"
#include "serial_robot_driver/devices/servo_bus/servo_params.h"

namespace serial_robot_driver::devices::servo_bus::sim {

using serial_robot_driver::sim::fromSeconds;
using serial_robot_driver::sim::Outbox;
using serial_robot_driver::sim::Outgoing;
using serial_robot_driver::sim::OutputKind;
using serial_robot_driver::sim::TimePoint;
using serial_robot_driver::sim::toSeconds;

const OutputKind kServoAnswerOutput{"servo_answers", 1};
using servo_bus::Command;

namespace {

// data_ids of docs/protocols.md, section 3 the simulator gives a behaviour to.
constexpr uint8_t kVoltage = dataId(ServoDataId::kVoltage);
constexpr uint8_t kCurrent = dataId(ServoDataId::kCurrent);
constexpr uint8_t kPower = dataId(ServoDataId::kPower);
constexpr uint8_t kTemperature = dataId(ServoDataId::kTemperature);
constexpr uint8_t kServoStatus = dataId(ServoDataId::kServoStatus);
constexpr uint8_t kServoType = dataId(ServoDataId::kServoType);
constexpr uint8_t kFirmwareVersion = dataId(ServoDataId::kFirmwareVersion);
constexpr uint8_t kSerialNumber = dataId(ServoDataId::kSerialNumber);
constexpr uint8_t kResponseSwitch = dataId(ServoDataId::kResponseSwitch);
constexpr uint8_t kServoId = dataId(ServoDataId::kServoId);
constexpr uint8_t kAngleLimitSwitch = dataId(ServoDataId::kAngleLimitSwitch);
constexpr uint8_t kAngleLimitHigh = dataId(ServoDataId::kAngleLimitHigh);
constexpr uint8_t kAngleLimitLow = dataId(ServoDataId::kAngleLimitLow);

constexpr int64_t kNominalVoltage = 7400;  // mV, a 2S LiPo
constexpr int64_t kNominalTemperature = 35;
constexpr int64_t kIdleCurrent = 20;  // mA
constexpr int64_t kMovingCurrent = 350;

constexpr auto kDriftPeriod = std::chrono::milliseconds(100);

// Factory values of the user block (assumption: datasheet-like numbers). The id goes back to the
// factory default 0 like on the real servo, so a reset on a chain may collide with servo 0.
const std::map<uint8_t, int64_t>& userDefaults() {
  static const std::map<uint8_t, int64_t> defaults = {
      {dataId(ServoDataId::kReserved32), 0},        {dataId(ServoDataId::kResponseSwitch), 0},
      {dataId(ServoDataId::kReserved35), 0},        {dataId(ServoDataId::kBaudrate), 5},
      {dataId(ServoDataId::kStallProtectMode), 1},  {dataId(ServoDataId::kStallPowerLimit), 4000},
      {dataId(ServoDataId::kOverVoltLow), 4500},    {dataId(ServoDataId::kOverVoltHigh), 14000},
      {dataId(ServoDataId::kOverTemperature), 65},  {dataId(ServoDataId::kOverPower), 12000},
      {dataId(ServoDataId::kOverCurrent), 3000},    {dataId(ServoDataId::kAccelSwitch), 1},
      {dataId(ServoDataId::kReserved45), 0},        {dataId(ServoDataId::kPoLockSwitch), 0},
      {dataId(ServoDataId::kWbLockSwitch), 0},      {dataId(ServoDataId::kAngleLimitSwitch), 0},
      {dataId(ServoDataId::kSoftStartSwitch), 0},   {dataId(ServoDataId::kSoftStartTime), 3000},
      {dataId(ServoDataId::kAngleLimitHigh), 1800}, {dataId(ServoDataId::kAngleLimitLow), -1800},
      {dataId(ServoDataId::kAngleMidOffset), 0},
  };
  return defaults;
}

int16_t toDecidegrees(double degrees) {
  constexpr double kMin = std::numeric_limits<int16_t>::min();
  constexpr double kMax = std::numeric_limits<int16_t>::max();
  return static_cast<int16_t>(std::lround(std::clamp(degrees * 10.0, kMin, kMax)));
}

// An angle folded into one turn, -180 .. 180.
double wrapDegrees(double degrees) {
  double wrapped = std::fmod(degrees + 180.0, 360.0);
  if (wrapped < 0) wrapped += 360.0;
  return wrapped - 180.0;
}

// The single-turn view of the multi-turn angle: unchanged within +-180, else folded into one turn.
double foldDegrees(double degrees) {
  return std::fabs(degrees) <= 180.0 ? degrees : wrapDegrees(degrees);
}

constexpr uint8_t kFactoryId = 0;
constexpr double kDegreesPerTurn = 360.0;
constexpr double kMsPerSecond = 1000.0;

}  // namespace

ServoBusSim::ServoBusSim(const ServoBusSimConfig& config, TimePoint now)
    : config_(config), rng_(config.seed), last_drift_(now) {
  for (uint8_t id : config_.servo_ids) {
    const bool offline = std::find(config_.offline_ids.begin(), config_.offline_ids.end(), id) !=
                         config_.offline_ids.end();
    if (offline || id == kBroadcastId) continue;
    Servo s;
    s.last_step = now;
    s.params[kVoltage] = kNominalVoltage;
    s.params[kCurrent] = kIdleCurrent;
    s.params[kPower] = kNominalVoltage * kIdleCurrent / 1000;
    s.params[kTemperature] = kNominalTemperature;
    s.params[kServoStatus] = 0;
    s.params[kServoType] = 0x0101;
    s.params[kFirmwareVersion] = 0x0102;
    s.params[kSerialNumber] = 0x53520000 + id;
    resetUserData(&s);
    s.params[kServoId] = id;  // configured on this chain
    if (auto held = config_.temperature_c.find(id); held != config_.temperature_c.end()) {
      s.params[kTemperature] = held->second;
    }
    if (auto held = config_.voltage_mv.find(id); held != config_.voltage_mv.end()) {
      s.params[kVoltage] = held->second;
    }
    // Its identity and response_switch where the configuration gives them (after the factory
    // user block, which holds response_switch).
    for (const auto& [data_id, values] : {std::pair{kServoType, &config_.servo_type},
                                          {kFirmwareVersion, &config_.firmware_version},
                                          {kSerialNumber, &config_.serial_number},
                                          {kResponseSwitch, &config_.response_switch}}) {
      if (auto given = values->find(id); given != values->end()) s.params[data_id] = given->second;
    }
    servos_.push_back(std::move(s));
  }
}

void ServoBusSim::resetUserData(Servo* s) const {
  for (const auto& [data_id, value] : userDefaults()) s->params[data_id] = value;
  s->params[kServoId] = kFactoryId;
}

void ServoBusSim::beginMove(Motion* m, double start_angle) {
  const double distance = std::fabs(m->target_angle - start_angle);
  if (m->velocity_dps > 0) {
    // Accelerate to the velocity, cruise, decelerate; a short move never reaches the cruise speed
    // (triangular profile over the same ramp times).
    double peak = m->velocity_dps;
    const double ramps = (m->accel_s + m->decel_s) / 2.0;
    if (distance < peak * ramps) peak = ramps > 0 ? distance / ramps : peak;
    m->peak_dps = peak;
    m->duration_s = peak > 0 ? distance / peak + ramps : 0.0;
    if (distance == 0.0) m->duration_s = 0.0;
  } else {
    // By interval: the ramps share the interval; ramps longer than it are shortened in proportion.
    const double ramp_sum = m->accel_s + m->decel_s;
    if (ramp_sum > m->duration_s && ramp_sum > 0) {
      const double scale = m->duration_s / ramp_sum;
      m->accel_s *= scale;
      m->decel_s *= scale;
    }
    const double cruise_time = m->duration_s - (m->accel_s + m->decel_s) / 2.0;
    m->peak_dps = cruise_time > 0 ? distance / cruise_time : 0.0;
  }
}

double ServoBusSim::moveAngle(const Motion& m, double elapsed) {
  if (elapsed >= m.duration_s || m.duration_s <= 0) return m.target_angle;
  const double direction = m.target_angle >= m.start_angle ? 1.0 : -1.0;
  const double v = m.peak_dps;
  double travelled = 0.0;
  if (elapsed < m.accel_s) {
    travelled = 0.5 * v / m.accel_s * elapsed * elapsed;
  } else if (elapsed < m.duration_s - m.decel_s) {
    travelled = 0.5 * v * m.accel_s + v * (elapsed - m.accel_s);
  } else {
    const double left = m.duration_s - elapsed;
    travelled = std::fabs(m.target_angle - m.start_angle) - 0.5 * v / m.decel_s * left * left;
  }
  return m.start_angle + direction * travelled;
}

void ServoBusSim::requestMove(Servo* s, Motion motion, uint8_t id, bool broadcast, TimePoint now) {
  if (!motion.multi_turn && param(*s, kAngleLimitSwitch) == 1) {
    motion.target_angle = std::clamp(motion.target_angle, param(*s, kAngleLimitLow) / 10.0,
                                     param(*s, kAngleLimitHigh) / 10.0);
  }
  motion.kind = Motion::Kind::kRotate;
  motion.answer = !broadcast && param(*s, kResponseSwitch) == 1;
  motion.answer_id = id;
  startMotion(s, motion, now);
}

int64_t ServoBusSim::param(const Servo& s, uint8_t data_id) {
  const auto it = s.params.find(data_id);
  return it == s.params.end() ? 0 : it->second;
}

void ServoBusSim::answer(TimePoint due, Command cmd, const std::vector<uint8_t>& content) {
  PendingAnswer pending{due, encodeResponse(cmd, content)};
  const auto position =
      std::upper_bound(pending_.begin(), pending_.end(), due,
                       [](TimePoint t, const PendingAnswer& other) { return t < other.due; });
  pending_.insert(position, std::move(pending));
}

void ServoBusSim::handleRequest(const uint8_t* data, std::size_t size, TimePoint now) {
  const auto decoded = decodeRequest(data, size);
  if (!decoded || decoded->content_size == 0) {
    ++stats_.malformed;
    return;
  }
  const Packet& packet = *decoded;
  ++stats_.requests;
  const uint8_t id = packet.id();
  const protocol::Decoded<SpinCommand> spin = decodeSpin(packet);
  if (spin && spin->mode == SpinMode::kStop && config_.lost_stops > 0) {
    --config_.lost_stops;
    ++stats_.stops_lost;
    return;
  }
  if (id == kBroadcastId) {
    ++stats_.broadcasts;
    for (Servo& s : servos_) execute(&s, packet, true, now);
    return;
  }
  // The address is the servo_id parameter, which a write may have changed.
  for (Servo& s : servos_) {
    if (param(s, kServoId) == id) {
      execute(&s, packet, false, now);
      return;
    }
  }
  ++stats_.unaddressed;
}

const std::array<ServoBusSim::HandlerRow, kMaxCommand>& ServoBusSim::handlers() {
  static constexpr std::array<HandlerRow, kMaxCommand> kRows = {{
      {Command::kPing, &ServoBusSim::onPing},
      {Command::kResetUserData, &ServoBusSim::onResetUserData},
      {Command::kReadData, &ServoBusSim::onReadData},
      {Command::kWriteData, &ServoBusSim::onWriteData},
      {Command::kReadBatchData, &ServoBusSim::onReadBatchData},
      {Command::kWriteBatchData, &ServoBusSim::onWriteBatchData},
      {Command::kSpin, &ServoBusSim::onSpin},
      {Command::kRotate, &ServoBusSim::onMove},
      {Command::kDamping, &ServoBusSim::onDamping},
      {Command::kReadAngle, &ServoBusSim::onReadAngle},
      {Command::kMoveByInterval, &ServoBusSim::onMove},
      {Command::kMoveByVelocity, &ServoBusSim::onMove},
      {Command::kMultiTurnMove, &ServoBusSim::onMove},
      {Command::kMultiTurnMoveByInterval, &ServoBusSim::onMove},
      {Command::kMultiTurnMoveByVelocity, &ServoBusSim::onMove},
      {Command::kReadMultiTurnAngle, &ServoBusSim::onReadMultiTurnAngle},
  }};
  static_assert(
      [] {
        for (std::size_t i = 0; i < kRows.size(); ++i) {
          if (commandRow(kRows[i].cmd) != i) return false;
        }
        return true;
      }(),
      "the handlers are in the order of servo::commandTable()");
  return kRows;
}

void ServoBusSim::execute(Servo* s, const Packet& packet, bool broadcast, TimePoint now) {
  runMotions(s, now);  // the angle and the queue as of this request
  const auto cmd = static_cast<Command>(packet.cmd);
  const CommandInfo& info = commandInfo(cmd);
  if (!info.request.fits(packet.content_size)) {
    ++stats_.malformed;
    return;
  }
  // Nobody answers the broadcast id; a motion answers (on completion) only with response_switch 1.
  const bool answers =
      !broadcast && (info.answers == Answers::kAlways || param(*s, kResponseSwitch) == 1);
  const Request request{s,         packet,  cmd, packet.id(),
                        broadcast, answers, now, now + fromSeconds(config_.answer_latency_s)};
  (this->*handlers()[commandRow(cmd)].handle)(request);
}

void ServoBusSim::reply(const Request& request, const std::vector<uint8_t>& content) {
  if (request.answers) answer(request.due, request.cmd, content);
}

void ServoBusSim::onMove(const Request& request) {
  const Command cmd = request.cmd;
  const protocol::Decoded<MoveCommand> move = decodeMove(request.packet);
  if (!move) {
    ++stats_.malformed;
    return;
  }
  Motion motion;
  motion.cmd = cmd;
  motion.multi_turn = isMultiTurn(cmd);
  motion.target_angle = move->angle_decidegrees / 10.0;
  if (isByVelocity(cmd)) {
    motion.velocity_dps = move->velocity_decidegrees_per_s / 10.0;
    if (motion.velocity_dps <= 0) {
      ++stats_.malformed;
      return;
    }
  } else {
    motion.duration_s = move->interval_ms / kMsPerSecond;
  }
  if (hasRamps(cmd)) {
    motion.accel_s = move->ramps.accel_ms / kMsPerSecond;
    motion.decel_s = move->ramps.decel_ms / kMsPerSecond;
  }
  requestMove(request.servo, motion, request.id, request.broadcast, request.now);
}

void ServoBusSim::onPing(const Request& request) { reply(request, pingAnswerContent(request.id)); }

void ServoBusSim::onResetUserData(const Request& request) {
  resetUserData(request.servo);
  // The servo now has its factory id and answers from there.
  reply(request, resultAnswerContent(kFactoryId, true));
}

const ParamInfo* ServoBusSim::dataRequest(const Request& request, DataContent* content) {
  const protocol::Decoded<DataContent> decoded = decodeDataContent(request.packet);
  if (!decoded) {
    ++stats_.malformed;
    return nullptr;
  }
  const ParamInfo* param_info = findParamById(decoded->data_id);
  if (param_info == nullptr) {
    ++stats_.unknown_data_ids;
    return nullptr;
  }
  *content = *decoded;
  return param_info;
}

void ServoBusSim::onReadData(const Request& request) {
  DataContent content;
  const ParamInfo* param_info = dataRequest(request, &content);
  if (param_info == nullptr) return;
  reply(request,
        readDataAnswerContent(request.id, *param_info, param(*request.servo, param_info->data_id)));
}

void ServoBusSim::onWriteData(const Request& request) {
  DataContent content;
  const ParamInfo* param_info = dataRequest(request, &content);
  if (param_info == nullptr) return;
  const auto value = readValue(*param_info, content.value.data(), content.value_size);
  if (!value) {
    ++stats_.malformed;
    return;
  }
  // The servo enforces ranges and read-only cells, not the host's notion of "dangerous".
  const bool ok = checkWrite(*param_info, *value, true) == WriteCheck::kOk;
  if (ok) {
    request.servo->params[param_info->data_id] = *value;
  } else {
    ++stats_.writes_rejected;
  }
  reply(request, writeDataAnswerContent(request.id, param_info->data_id, ok));
}

void ServoBusSim::onReadBatchData(const Request& request) {
  const auto value_of = [&](const ParamInfo& info) { return param(*request.servo, info.data_id); };
  reply(request, userBlockAnswerContent(request.id, packUserBlock(value_of)));
}

void ServoBusSim::onWriteBatchData(const Request& request) {
  const auto block = decodeUserBlock(request.packet);
  if (!block) {
    ++stats_.malformed;
    return;
  }
  const auto values = unpackUserBlock(*block);
  // All or nothing: one bad cell rejects the block.
  const bool ok = std::all_of(values.begin(), values.end(), [](const auto& cell) {
    return checkWrite(*cell.first, cell.second, true) == WriteCheck::kOk;
  });
  if (ok) {
    for (const auto& [param_info, value] : values)
      request.servo->params[param_info->data_id] = value;
  } else {
    ++stats_.writes_rejected;
  }
  reply(request, resultAnswerContent(request.id, ok));
}

void ServoBusSim::onSpin(const Request& request) {
  const protocol::Decoded<SpinCommand> spin = decodeSpin(request.packet);
  if (!spin) {
    ++stats_.malformed;
    return;
  }
  Servo* s = request.servo;
  const double speed = spin->speed_dps;
  const double rate = spin->clockwise ? -speed : speed;  // clockwise is negative
  Motion motion;
  motion.kind = Motion::Kind::kSpin;
  motion.cmd = Command::kSpin;
  motion.answer = request.answers;
  motion.answer_id = request.id;
  motion.rate_dps = rate;
  switch (spin->mode) {
    case SpinMode::kStop:
      stopAll(s);
      reply(request, resultAnswerContent(request.id, true));
      return;
    case SpinMode::kContinuous:
      stopAll(s);
      s->relaxed = false;
      s->spin_rate_dps = rate;
      reply(request, resultAnswerContent(request.id, true));
      return;
    case SpinMode::kTurns:
      motion.duration_s = speed > 0 ? spin->value * 360.0 / speed : 0.0;
      break;
    case SpinMode::kDurationMs:
      motion.duration_s = spin->value / 1000.0;
      break;
  }
  startMotion(s, motion, request.now);
}

void ServoBusSim::onReadMultiTurnAngle(const Request& request) {
  const double angle_deg = request.servo->angle_deg;
  MultiTurnAngle reading;
  reading.id = request.id;
  const double decidegrees =
      std::clamp(std::round(angle_deg * 10.0), double(std::numeric_limits<int32_t>::min()),
                 double(std::numeric_limits<int32_t>::max()));
  reading.angle_decidegrees = static_cast<int32_t>(decidegrees);
  reading.turns = static_cast<int16_t>(std::trunc(angle_deg / kDegreesPerTurn));
  reply(request, multiTurnAngleContent(reading));
}

void ServoBusSim::onDamping(const Request& request) {
  stopAll(request.servo);  // damping releases the holding torque: nothing keeps moving
  request.servo->relaxed = true;
  reply(request, resultAnswerContent(request.id, true));
}

void ServoBusSim::onReadAngle(const Request& request) {
  reply(request, angleAnswerContent(AngleAnswer{
                     request.id, toDecidegrees(foldDegrees(request.servo->angle_deg))}));
}

void ServoBusSim::stopAll(Servo* s) {
  s->motions.clear();
  s->spin_rate_dps = 0.0;
}

void ServoBusSim::startMotion(Servo* s, Motion motion, TimePoint now) {
  if (!motion.answer) stopAll(s);  // response_switch 0: the new command interrupts
  s->spin_rate_dps = 0.0;
  s->relaxed = false;
  s->motions.push_back(motion);
  runMotions(s, now);
}

void ServoBusSim::runMotions(Servo* s, TimePoint now) {
  if (s->spin_rate_dps != 0.0) {
    s->angle_deg += s->spin_rate_dps * toSeconds(now - s->last_step);  // turns accumulate
  }
  s->last_step = now;
  TimePoint cursor = now;
  while (!s->motions.empty()) {
    Motion& motion = s->motions.front();
    if (!motion.started) {
      motion.started = true;
      motion.start = cursor;
      if (motion.kind == Motion::Kind::kRotate && !motion.multi_turn) {
        s->angle_deg = foldDegrees(s->angle_deg);  // a single-turn move works within one turn
      }
      motion.start_angle = s->angle_deg;
      if (motion.kind == Motion::Kind::kRotate) beginMove(&motion, motion.start_angle);
    }
    const double elapsed = toSeconds(now - motion.start);
    const bool done = elapsed >= motion.duration_s;
    const double progress = done ? motion.duration_s : elapsed;
    if (motion.kind == Motion::Kind::kRotate) {
      s->angle_deg = moveAngle(motion, progress);
    } else {
      s->angle_deg = motion.start_angle + motion.rate_dps * progress;
    }
    if (!done) break;
    const TimePoint finished = motion.start + fromSeconds(motion.duration_s);
    if (motion.answer) {
      answer(std::max(finished, now) + fromSeconds(config_.answer_latency_s), motion.cmd,
             resultAnswerContent(motion.answer_id, true));
    }
    cursor = finished;  // the next queued motion starts where this one ended
    s->motions.pop_front();
  }
}

void ServoBusSim::driftReadOnly(Servo* s) {
  std::uniform_int_distribution<int> step(-1, 1);
  const bool moving = !s->motions.empty() || s->spin_rate_dps != 0.0;
  const auto id = static_cast<uint8_t>(param(*s, kServoId));
  const bool voltage_held = config_.voltage_mv.count(id) > 0;
  const bool temperature_held = config_.temperature_c.count(id) > 0;
  int64_t& voltage = s->params[kVoltage];
  if (!voltage_held) {
    voltage =
        std::clamp<int64_t>(voltage + 5 * step(rng_), kNominalVoltage - 60, kNominalVoltage + 60);
  }
  int64_t& temperature = s->params[kTemperature];
  if (!temperature_held && std::uniform_int_distribution<int>(0, 49)(rng_) == 0) {
    temperature = std::clamp<int64_t>(temperature + step(rng_), kNominalTemperature - 1,
                                      kNominalTemperature + 2);
  }
  const int64_t current =
      (moving ? kMovingCurrent : kIdleCurrent) + std::uniform_int_distribution<int>(0, 5)(rng_);
  s->params[kCurrent] = current;
  s->params[kPower] = voltage * current / 1000;
}

void ServoBusSim::tick(TimePoint now, Outbox* out) {
  const bool drift = now - last_drift_ >= kDriftPeriod;
  if (drift) last_drift_ = now;
  for (Servo& s : servos_) {
    runMotions(&s, now);
    if (drift) driftReadOnly(&s);
  }
  while (!pending_.empty() && pending_.front().due <= now) {
    out->push_back(
        Outgoing{&kServoAnswerOutput, std::move(pending_.front().bytes), pending_.front().due});
    pending_.pop_front();
    ++stats_.answers;
  }
}

TimePoint ServoBusSim::nextEvent() const {
  TimePoint next = last_drift_ + kDriftPeriod;
  if (!pending_.empty()) next = std::min(next, pending_.front().due);
  for (const Servo& s : servos_) {
    if (s.motions.empty()) continue;
    const Motion& motion = s.motions.front();
    if (motion.started) next = std::min(next, motion.start + fromSeconds(motion.duration_s));
  }
  return next;
}

ServoBusSimStats ServoBusSim::stats() const {
  ServoBusSimStats copy = stats_;
  copy.servos.clear();
  for (const Servo& s : servos_) {
    BusServoSnapshot snapshot;
    snapshot.id = static_cast<uint8_t>(param(s, kServoId));
    snapshot.angle_deg = s.angle_deg;
    snapshot.moving = !s.motions.empty() || s.spin_rate_dps != 0.0;
    snapshot.relaxed = s.relaxed;
    snapshot.params = s.params;
    copy.servos.push_back(std::move(snapshot));
  }
  return copy;
}

}  // namespace serial_robot_driver::devices::servo_bus::sim
