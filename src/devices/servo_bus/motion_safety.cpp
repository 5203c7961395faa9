#include "serial_robot_driver/devices/servo_bus/motion_safety.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "servo_bus_text.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

std::string servoLabel(uint8_t id) { return "servo " + std::to_string(id); }

/// The parameters that change where or how a servo moves, or where its stop goes.
bool affectsMotion(uint8_t data_id) {
  constexpr std::array<ServoDataId, 10> kMotionParams = {
      ServoDataId::kServoId,          ServoDataId::kBaudrate,        ServoDataId::kResponseSwitch,
      ServoDataId::kStallProtectMode, ServoDataId::kStallPowerLimit, ServoDataId::kAccelSwitch,
      ServoDataId::kAngleLimitSwitch, ServoDataId::kAngleLimitHigh,  ServoDataId::kAngleLimitLow,
      ServoDataId::kAngleMidOffset};
  return std::any_of(kMotionParams.begin(), kMotionParams.end(),
                     [&](ServoDataId id) { return dataId(id) == data_id; });
}

ServoStatus eStopRefusal(uint8_t id) {
  return {ServoError::kMotionRefused,
          "e_stop is engaged: " + servoLabel(id) + " does not move until it is released"};
}

}  // namespace

std::optional<ShutdownAction> shutdownActionFromString(const std::string& text) {
  if (text == "stop") return ShutdownAction::kStop;
  if (text == "relax") return ShutdownAction::kRelax;
  if (text == "none") return ShutdownAction::kNone;
  return std::nullopt;
}

const char* toString(ShutdownAction action) {
  switch (action) {
    case ShutdownAction::kStop:
      return "stop";
    case ShutdownAction::kRelax:
      return "relax";
    case ShutdownAction::kNone:
      return "none";
  }
  return "?";
}

MotionSafety::MotionSafety(const std::vector<uint8_t>& polled_ids, const ServoBusConfig& settings,
                           ServoBusClient& client, const ServoBusEvents& events,
                           core::LoopClock& clock, std::mutex& mutex, StopKeeper& stops,
                           const ServoPoller& poller, Hooks hooks)
    : polled_ids_(polled_ids),
      settings_(settings),
      client_(client),
      events_(events),
      clock_(clock),
      mutex_(mutex),
      stops_(stops),
      poller_(poller),
      hooks_(std::move(hooks)) {}

void MotionSafety::noteCommanded(uint8_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  commanded_.insert(id);
  stops_.eraseLocked(id);  // the gate was open: the e-stop is not engaged, this was a hold's stop
}

void MotionSafety::noteMotion(uint8_t id, bool moving) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (moving) {
    moving_.insert(id);
  } else if (id == kBroadcastId) {
    moving_.clear();  // a broadcast stop or relax reached every servo
  } else {
    moving_.erase(id);
  }
}

ServoStatus MotionSafety::refusal(uint8_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return refusalLocked(id);
}

ServoStatus MotionSafety::accept(uint8_t id, core::MotionGate::Generation* generation) const {
  if (id == kBroadcastId) {
    return {ServoError::kInvalidArgument,
            "motions to id 255 (broadcast) are refused: nothing answers them, so the driver could "
            "not tell which servos they set moving nor stop them one by one; command each servo "
            "by its id (a broadcast SPIN stop or DAMPING is allowed)"};
  }
  // The generation first: an e-stop engaged after this line voids the command at the write, one
  // engaged before it is still engaged below (or was released: the command came after it).
  *generation = gate_.generation();
  if (gate_.state() == core::GateState::kLocked) return eStopRefusal(id);
  return refusal(id);
}

ServoStatus MotionSafety::refusalLocked(uint8_t id) const {
  if (motion_locked_) return eStopRefusal(id);
  if (const ServoHealthReport* overheated = poller_.overheatedLocked(id)) {
    const ServoHealthReport& report = *overheated;
    return {ServoError::kMotionRefused,
            servoLabel(id) + " is relaxed: its temperature reached its over_temperature limit (" +
                std::to_string(report.readings.temperature_c) + " degC, limit " +
                std::to_string(report.limits.over_temperature_c) + " degC); moves are refused " +
                "until it has cooled to " +
                std::to_string(report.limits.over_temperature_c - OverheatGuard::kCoolDownC) +
                " degC"};
  }
  return {};
}

ServoStatus MotionSafety::move(const MoveRequest& request) {
  core::MotionGate::Generation generation = 0;
  ServoStatus status = accept(request.id, &generation);
  if (!status.ok()) return status;
  status = client_.move(request, BusPriority::kCaller, generation);
  if (status.ok()) noteMotion(request.id, true);
  return status;
}

ServoStatus MotionSafety::rotate(const RotateRequest& request) {
  core::MotionGate::Generation generation = 0;
  ServoStatus status = accept(request.id, &generation);
  if (!status.ok()) return status;
  status = client_.rotate(request, generation);
  if (status.ok()) noteMotion(request.id, true);
  return status;
}

ServoStatus MotionSafety::spin(const SpinRequest& request) {
  // A SPIN stop is always let through: it is what the e-stop itself sends.
  const bool stop = request.mode == 0;
  core::MotionGate::Generation generation = 0;
  ServoStatus status = stop ? ServoStatus{} : accept(request.id, &generation);
  if (!status.ok()) return status;
  status = client_.spin(request, stop ? std::nullopt : std::optional(generation));
  if (status.ok()) noteMotion(request.id, !stop);
  return status;
}

ServoStatus MotionSafety::damping(uint8_t id, uint16_t power_mw, bool wait) {
  // Torque off moves nothing actively: a safety action, allowed while the e-stop holds.
  const ServoStatus status = client_.damping(id, power_mw, wait, FrameGate::kSafetyAction);
  if (!status.ok()) return status;
  noteMotion(id, false);  // no holding torque: nothing keeps it moving or in place
  // A broadcast is not answered: which servos heard it is unknown, their stops stay.
  if (id == kBroadcastId) return status;
  std::lock_guard<std::mutex> lock(mutex_);
  commanded_.erase(id);
  stops_.eraseLocked(id);  // relaxed: its stop is satisfied (another would give it torque back)
  return status;
}

ServoStatus MotionSafety::relax(const std::vector<uint8_t>& ids) {
  const std::vector<uint8_t>& targets = ids.empty() ? polled_ids_ : ids;
  if (targets.empty()) {
    return {ServoError::kInvalidArgument,
            "no servo given and none configured (state_ids, joint_ids)"};
  }
  uint16_t power_mw = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    power_mw = settings_.relax_power_mw;
  }
  for (uint8_t id : targets) {
    const ServoStatus status = damping(id, power_mw, false);
    if (!status.ok()) return status;
  }
  return {ServoError::kOk, std::to_string(targets.size()) + " servo(s) relaxed (DAMPING " +
                               std::to_string(power_mw) + " mW)"};
}

ServoStatus MotionSafety::hold(const std::vector<uint8_t>& ids) {
  const std::vector<uint8_t>& targets = ids.empty() ? polled_ids_ : ids;
  if (targets.empty()) {
    return {ServoError::kInvalidArgument,
            "no servo given and none configured (state_ids, joint_ids)"};
  }
  std::string held;
  std::optional<core::MotionGate::Generation> accepted;  // the call's: noted at its first check
  for (uint8_t id : targets) {
    core::MotionGate::Generation generation = 0;
    ServoStatus status = accept(id, &generation);
    if (!status.ok()) return status;
    if (!accepted) accepted = generation;
    double angle_deg = 0.0;
    // A hold is a stop: its bus turns are urgent work (BusPriority::kStop).
    status = client_.readAngle(id, &angle_deg, nullptr, BusPriority::kStop);
    if (!status.ok()) return status;
    RotateRequest request;
    request.id = id;
    request.angle_deg = angle_deg;
    request.priority = BusPriority::kStop;
    status = client_.rotate(request, accepted);
    if (!status.ok()) return status;
    noteMotion(id, false);  // holding where it is: not set moving
    char text[48];
    std::snprintf(text, sizeof(text), "%s%u at %.1f deg", held.empty() ? "" : ", ", id, angle_deg);
    held += text;
  }
  return {ServoError::kOk, "holding servo(s) " + held};
}

ServoStatus MotionSafety::settingRefusal(uint8_t id, const std::string& what) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (motion_locked_) {
    return {ServoError::kMotionRefused,
            "e_stop is engaged: " + what + " of " + servoLabel(id) +
                " is refused until it is released (it changes how or where the servo moves, or "
                "where its stop goes)"};
  }
  if (moving_.count(id) > 0 || stops_.keptLocked(id)) {
    return {ServoError::kMotionRefused,
            what + " of " + servoLabel(id) +
                " is refused while it moves (set moving and not stopped since, or its stop not "
                "yet confirmed): stop it first (servo/spin mode 0, or servo/relax)"};
  }
  return {};
}

ServoStatus MotionSafety::writeParam(uint8_t id, std::string_view param, int64_t value) {
  const ParamInfo* info = findParam(param);
  if (info != nullptr && affectsMotion(info->data_id)) {
    const ServoStatus refused = settingRefusal(id, "a write of '" + std::string(info->name) + "'");
    if (!refused.ok()) return refused;
  }
  const ServoStatus status = client_.writeParam(id, param, value);
  if (status.ok() && info != nullptr && info->data_id == dataId(ServoDataId::kServoId) &&
      value != id) {
    followAddress(id, static_cast<uint8_t>(value));
  }
  return status;
}

ServoStatus MotionSafety::resetUserData(uint8_t id) {
  // The reset restores the factory angle limits and id: as much a motion setting as any.
  const ServoStatus refused = settingRefusal(id, "RESET_USER_DATA");
  if (!refused.ok()) return refused;
  const ServoStatus status = client_.resetUserData(id);
  if (status.ok()) followAddress(id, kServoIdAfterReset);
  return status;
}

void MotionSafety::followAddress(uint8_t from, uint8_t to) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (from == to) return;
  if (commanded_.erase(from) > 0) commanded_.insert(to);
  if (moving_.erase(from) > 0) moving_.insert(to);
  stops_.renameLocked(from, to);
}

bool MotionSafety::motionLocked() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return motion_locked_;
}

std::vector<uint8_t> MotionSafety::movingIds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {moving_.begin(), moving_.end()};
}

std::vector<uint8_t> MotionSafety::commandedIds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {commanded_.begin(), commanded_.end()};
}

void MotionSafety::noteStopWrittenLocked(uint8_t id) {
  if (id == kBroadcastId) moving_.clear();
  moving_.erase(id);
}

void MotionSafety::setMotionLocked(bool locked) {
  // First the gate: from its return on no motion frame is written, whoever is waiting to.
  gate_.setLocked(locked);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    motion_locked_ = locked;
    if (!locked) {
      stops_.releaseLocked();  // the stops that went out are done; one never written still goes
      return;
    }
    hooks_.drop_queued_moves_locked();
    const core::Clock::time_point now = clock_.now();
    for (uint8_t id : commanded_) stops_.armLocked(id, now, /*repeat=*/true);
    if (stops_.emptyLocked()) return;
  }
  hooks_.deliver_stops();
}

bool MotionSafety::rearmStopsLocked(core::Clock::time_point now) {
  if (motion_locked_) {
    for (uint8_t id : commanded_) stops_.armLocked(id, now, /*repeat=*/true);
  }
  stops_.rearmAllLocked(now);
  return !stops_.emptyLocked();
}

void MotionSafety::finalWords() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (final_words_said_) return;
    final_words_said_ = true;
  }
  ServoBusConfig in_force;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    in_force = settings_;
  }
  const auto deadline = std::chrono::steady_clock::now() + kShutdownStopBudget;
  std::unique_lock<std::mutex> lock(mutex_);
  switch (in_force.on_shutdown) {
    case ShutdownAction::kStop: {
      const core::Clock::time_point now = clock_.now();
      stops_.endRepeatsLocked();  // each ends once seen at rest: the budget is short
      for (uint8_t id : commanded_) stops_.armLocked(id, now);
      // Back to back on this thread (the worker has stopped), until each is seen at rest.
      while (!stops_.emptyLocked() && std::chrono::steady_clock::now() < deadline) {
        // A port that is down has nothing to gain from a busy loop.
        if (stops_.portDownLocked()) {
          lock.unlock();
          std::this_thread::sleep_for(StopKeeper::kStopRetry);
          lock.lock();
        }
        stops_.workOnce(lock, StopPace::kNow);
      }
      break;
    }
    case ShutdownAction::kRelax: {
      const std::vector<uint8_t> ids(commanded_.begin(), commanded_.end());
      lock.unlock();
      for (uint8_t id : ids) {
        // A write that failed (port down) is tried again until the budget is spent.
        while (
            !client_.damping(id, in_force.relax_power_mw, false, FrameGate::kSafetyAction).ok() &&
            std::chrono::steady_clock::now() < deadline) {
          std::this_thread::sleep_for(StopKeeper::kStopRetry);
        }
      }
      lock.lock();
      break;
    }
    case ShutdownAction::kNone:
      break;
  }
  const std::vector<std::pair<uint8_t, std::string>> unconfirmed = stops_.unconfirmedLocked();
  stops_.endUrgentLocked();  // the callers still waiting get the bus (and kShutdown)
  lock.unlock();
  for (const auto& [id, why] : unconfirmed) {
    if (events_.on_stop) {
      events_.on_stop(id, {ServoError::kShutdown, servo_text::servoName(id) +
                                                      "'s stop not confirmed at shutdown: " + why});
    }
  }
}

}  // namespace serial_robot_driver::devices::servo_bus
