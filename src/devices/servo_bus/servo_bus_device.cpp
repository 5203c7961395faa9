#include "serial_robot_driver/devices/servo_bus/servo_bus_device.h"

#include <algorithm>
#include <utility>

namespace serial_robot_driver::devices::servo_bus {

using core::log;
using core::LogLevel;

namespace {

constexpr double kMsPerSecond = 1000.0;

}  // namespace

/// The core says "dangerous"; the message says which parameter arms such writes.
std::string servoStatusMessage(const ServoStatus& status) {
  if (status.error != ServoError::kDangerous) return status.message;
  return status.message + " (set ~servo_bus/allow_dangerous_writes to true to arm it)";
}

ServoBusConfig makeServoBusConfig(const ServoBusParams& params) {
  ServoBusConfig config = params.bus;
  for (int id : params.state_ids) config.polled_ids.push_back(static_cast<uint8_t>(id));
  // Joint servos are polled too: their angles are the trajectories' measurements.
  for (int id : params.joint_ids) {
    const auto joint_id = static_cast<uint8_t>(id);
    if (std::find(config.polled_ids.begin(), config.polled_ids.end(), joint_id) ==
        config.polled_ids.end()) {
      config.polled_ids.push_back(joint_id);
    }
  }
  for (int id : params.joint_ids) config.identity.joint_ids.push_back(static_cast<uint8_t>(id));
  return config;
}

ServoBusDevice::ServoBusDevice(const params::DriverParams& params, core::SerialLink& link)
    : bus_joints_(makeBusJoints(params.section(kServoBusSection))),
      state_rate_(params.section(kServoBusSection).bus.poll_rate),
      bus_(makeServoBusConfig(params.section(kServoBusSection)), link.writer(), makeEvents()),
      claims_(bus_, bus_joints_),
      command_interval_ms_(
          static_cast<uint16_t>(params.section(kServoBusSection).command_interval_ms)),
      diagnostics_(bus_, link) {
  // The bus's worker (the poll, the queued moves) runs on the port's reader thread: a poll writes
  // its request and reads the answer itself, with no second thread to wake per transaction.
  bus_.runOn(link);
  if (params.section(kServoBusSection).bus.client.allow_dangerous_writes) {
    log(LogLevel::kWarn,
        "servo_bus: dangerous writes (servo_id, baudrate, response_switch, reserved cells, "
        "reset_user_data) are ARMED");
  }
}

ServoBusDevice::~ServoBusDevice() { shutdown(); }

ServoBusEvents ServoBusDevice::makeEvents() {
  ServoBusEvents events;
  // On the bus worker thread.
  events.on_angle = [this](const ServoAngleSample& sample) {
    const JointPosition state = busJointPosition(bus_joints_, sample.id, sample.angle_deg);
    for (const ServoBusOutputs& outputs : outputs_) {
      if (outputs.servo_state) outputs.servo_state(state, sample.arrival);
    }
    if (trajectory::TrajectoryExecutor* trajectories = claims_.trajectories()) {
      trajectories->updateActual({state.name}, {state.position}, {});
    }
  };
  events.on_servo_silent = [this](uint8_t id, const ServoStatus& status,
                                  std::chrono::milliseconds backoff) {
    if (!silent_log_.pass()) return;
    log(LogLevel::kWarn, "servo_states: %s does not answer (%s); asked again in %.1f s",
        servoJointName(id).c_str(), status.message.c_str(), backoff.count() / kMsPerSecond);
  };
  events.on_overheat = [](const ServoHealthReport& report) {
    if (report.overheated) {
      log(LogLevel::kError,
          "servo_bus: %s at %ld degC reached its over_temperature limit (%ld degC): relaxed, "
          "its moves refused until it has cooled %ld degC (~servo_bus/protect)",
          servoJointName(report.id).c_str(), static_cast<long>(report.readings.temperature_c),
          static_cast<long>(report.limits.over_temperature_c),
          static_cast<long>(OverheatGuard::kCoolDownC));
    } else {
      log(LogLevel::kInfo, "servo_bus: %s has cooled to %ld degC: its moves are obeyed again",
          servoJointName(report.id).c_str(), static_cast<long>(report.readings.temperature_c));
    }
  };
  // Once per servo, when it first answered: what it is, and what does not fit (once each).
  events.on_identity = [](const ServoIdentityReport& report) {
    log(LogLevel::kInfo, "servo_bus: %s: %s, angle limits %s", servoJointName(report.id).c_str(),
        describeIdentity(report.identity).c_str(), describeAngleLimits(report.identity).c_str());
    for (const std::string& warning : report.warnings) {
      log(LogLevel::kWarn, "servo_bus: %s", warning.c_str());
    }
  };
  events.on_move_failed = [this](const MoveRequest& move, const ServoStatus& status) {
    if (!move_failed_log_.pass()) return;
    log(LogLevel::kWarn, "servo_commands: %s not sent: %s", servoJointName(move.id).c_str(),
        servoStatusMessage(status).c_str());
  };
  events.on_stop = [this](uint8_t id, const ServoStatus& status) {
    if (status.ok()) {
      log(LogLevel::kInfo, "servo_bus: %s stopped: %s", servoJointName(id).c_str(),
          status.message.c_str());
    } else if (status.error == ServoError::kShutdown) {
      log(LogLevel::kError, "servo_bus: %s", status.message.c_str());
    } else if (stop_log_.pass()) {
      log(LogLevel::kWarn, "servo_bus: %s's stop not yet confirmed, writing it again: %s",
          servoJointName(id).c_str(), status.message.c_str());
    }
  };
  return events;
}

std::string ServoBusDevice::commandServos(const ServoJointCommand& command) {
  if (!claims_.refuseWhileEStopped("servo_commands").ok()) {
    const char* why = "servo_commands refused, nothing sent: e_stop is engaged";
    if (e_stop_log_.pass()) log(LogLevel::kWarn, "%s", why);
    return why;
  }
  const ServoCommandBatch batch = toServoMoves(command.names, command.positions, command.velocities,
                                               command_interval_ms_.load());
  if (!batch.error.empty()) {
    commands_rejected_.fetch_add(1);
    inputRefusals().refused("servo_commands");
    const std::string why = "servo_commands rejected, nothing sent: the message " + batch.error;
    if (rejected_log_.pass()) log(LogLevel::kWarn, "%s", why.c_str());
    return why;
  }
  // A joint servo under a trajectory is taken over by this command, and its goal aborted.
  claims_.queueCommand(batch.moves, "servo_commands");
  return {};
}

void ServoBusDevice::retune(const ServoBusParams& tuned) {
  bus_.retune(makeServoBusConfig(tuned));
  command_interval_ms_.store(static_cast<uint16_t>(tuned.command_interval_ms));
  claims_.followPollRate(tuned.bus.poll_rate);
}

void ServoBusDevice::retune(const params::DriverParams& in_force) {
  retune(in_force.section(kServoBusSection));
}

void ServoBusDevice::attachEStop(core::EStop& e_stop) {
  claims_.attachEStop(e_stop);
  // On the e_stop subscriber's thread, and it never waits for the bus: the gate is locked (no
  // motion frame from now on) and the stops are handed to the bus's worker, which writes them
  // ahead of everything else and keeps writing them until each servo is seen at rest.
  e_stop.addListener([this](bool engaged) {
    bus_.setMotionLocked(engaged);
    const std::vector<uint8_t> commanded = bus_.commandedIds();
    if (engaged && !commanded.empty()) {
      log(LogLevel::kWarn,
          "e_stop: stopping bus servo(s) %s (each stop is written until the servo is seen at "
          "rest)",
          servoIdList(commanded).c_str());
    }
  });
}

std::vector<core::Device::NamedStatus> ServoBusDevice::extraStatuses() {
  std::vector<NamedStatus> statuses;
  for (uint8_t id : bus_.config().polled_ids) {
    statuses.push_back({"servo_bus servo " + std::to_string(id),
                        [this, id] { return diagnostics_.servoStatus(id); }});
  }
  return statuses;
}

std::vector<trajectory::TrajectoryJoints> ServoBusDevice::trajectoryJoints() {
  const auto queue_move = [this](uint8_t id, double angle_deg, uint32_t interval_ms) {
    MoveRequest move;
    move.id = id;
    move.angle_deg = angle_deg;
    move.interval_ms = interval_ms;
    bus_.queueMoves({move});
    return std::string();
  };
  // A stop holds a joint with a SPIN stop: written ahead of queued moves, allowed while the
  // e-stop holds, and never a move to an angle that may be a poll period old.
  const auto stop_servo = [this](uint8_t id) {
    bus_.stopServo(id);
    return std::string();
  };
  return {busTrajectoryJoints(bus_joints_, queue_move, state_rate_, stop_servo)};
}

void ServoBusDevice::start() {
  if (started_ || shut_down_) return;
  started_ = true;
  bus_.start();
}

void ServoBusDevice::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  bus_.shutdown();  // fails a call waiting on the bus, so the front ends' calls end quickly
}

}  // namespace serial_robot_driver::devices::servo_bus
