#include "serial_robot_driver/ros/servo_bus_interface.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

namespace {

constexpr int kSpinnerThreads = 2;
constexpr double kMsPerSecond = 1000.0;
constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr int kMaxBusId = 254;  // 255 is the broadcast address
constexpr double kWarnThrottleS = 5.0;

void logOutcome(const std::string& service, const device::ServoStatus& status) {
  if (status.ok()) {
    ROS_DEBUG("%s: %s", service.c_str(), status.message.c_str());
  } else {
    ROS_DEBUG("%s failed (%s): %s", service.c_str(), device::toString(status.error),
              status.message.c_str());
  }
}

/// The core says "dangerous"; only this layer knows which parameter arms such writes.
std::string messageFor(const device::ServoStatus& status) {
  if (status.error != device::ServoError::kDangerous) return status.message;
  return status.message + " (set ~servo_bus/allow_dangerous_writes to true to arm it)";
}

// The outcome fields every servo/* response has; servo/ping calls its flag `online`.
template <typename Response>
void setOutcome(Response& res, bool ok, const std::string& message) {
  res.success = ok;
  res.message = message;
}
void setOutcome(ServoPing::Response& res, bool ok, const std::string& message) {
  res.online = ok;
  res.message = message;
}
// servo/scan has no flag: the ids it found are the outcome.
void setOutcome(ServoScan::Response& res, bool /*ok*/, const std::string& message) {
  res.message = message;
}

/// Whether a successful call is logged at INFO (it changed a servo's settings) or DEBUG only.
enum class Announce { kDebug, kInfo };

/// The client operation behind one service: it fills the response's own fields (values, angle)
/// and returns the status; the outcome fields are filled by advertiseServo().
template <typename Service>
using ServoCall =
    std::function<device::ServoStatus(typename Service::Request&, typename Service::Response&)>;

/// Advertises one servo/* service from its call. The service logs the outcome, never throws
/// through to its caller and always returns true, so the caller gets the message instead of a bare
/// "service call failed".
template <typename Service>
ros::ServiceServer advertiseServo(ros::NodeHandle& nh, const std::string& name,
                                  ServoCall<Service> call, Announce announce = Announce::kDebug) {
  using Request = typename Service::Request;
  using Response = typename Service::Response;
  const boost::function<bool(Request&, Response&)> serve = [name, call, announce](Request& req,
                                                                                  Response& res) {
    try {
      const device::ServoStatus status = call(req, res);
      logOutcome(name, status);
      if (status.ok() && announce == Announce::kInfo) {
        ROS_INFO("%s: %s", name.c_str(), status.message.c_str());
      }
      setOutcome(res, status.ok(), messageFor(status));
    } catch (const std::exception& error) {
      ROS_ERROR("%s: internal error: %s", name.c_str(), error.what());
      res = Response();
      setOutcome(res, false, std::string("internal error: ") + error.what());
    }
    return true;
  };
  return nh.advertiseService<Request, Response>(name, serve);
}

}  // namespace

std::string servoJointName(uint8_t id) { return "servo_" + std::to_string(id); }

int servoIdFromJointName(const std::string& name) {
  static const std::string kPrefix = "servo_";
  if (name.size() <= kPrefix.size() || name.size() > kPrefix.size() + 3 ||
      name.compare(0, kPrefix.size(), kPrefix) != 0) {
    return -1;
  }
  int id = 0;
  for (std::size_t i = kPrefix.size(); i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
    id = id * 10 + (name[i] - '0');
  }
  // "servo_007" is not the canonical name of servo 7: refuse rather than guess.
  if (name != servoJointName(static_cast<uint8_t>(std::min(id, 255)))) return -1;
  return id <= kMaxBusId ? id : -1;
}

ServoCommandBatch toServoMoves(const sensor_msgs::JointState& msg, uint16_t interval_ms) {
  ServoCommandBatch batch;
  if (msg.position.size() != msg.name.size()) {
    batch.error = "has " + std::to_string(msg.name.size()) + " names but " +
                  std::to_string(msg.position.size()) + " positions";
    return batch;
  }
  if (!msg.velocity.empty() && msg.velocity.size() != msg.name.size()) {
    batch.error = "has " + std::to_string(msg.name.size()) + " names but " +
                  std::to_string(msg.velocity.size()) + " velocities (give none or one per name)";
    return batch;
  }
  for (std::size_t i = 0; i < msg.name.size(); ++i) {
    const int id = servoIdFromJointName(msg.name[i]);
    if (id < 0) {
      batch.error = "names '" + msg.name[i].substr(0, 40) +
                    "', which is not a bus servo (expected servo_<id>, id 0..254)";
      break;
    }
    const double position = msg.position[i];
    const double velocity = msg.velocity.empty() ? 0.0 : msg.velocity[i];
    if (!std::isfinite(position) || !std::isfinite(velocity)) {
      batch.error = "has a non-finite position or velocity for " + msg.name[i];
      break;
    }
    device::MoveRequest move;
    move.id = static_cast<uint8_t>(id);
    move.angle_deg = position * kDegreesPerRadian;
    // The sign of the motion is the target's; a velocity is a speed.
    move.velocity_dps = std::fabs(velocity) * kDegreesPerRadian;
    move.interval_ms = interval_ms;
    batch.moves.push_back(move);
  }
  if (!batch.error.empty()) batch.moves.clear();
  return batch;
}

device::ServoBusOptions makeServoBusOptions(const DriverParams& params) {
  device::ServoBusOptions options;
  options.timeout =
      std::chrono::milliseconds(std::llround(params.servo_bus.timeout * kMsPerSecond));
  options.retries = params.servo_bus.retries;
  options.allow_dangerous_writes = params.servo_bus.allow_dangerous_writes;
  return options;
}

device::ServoBusConfig makeServoBusConfig(const DriverParams& params) {
  device::ServoBusConfig config;
  config.client = makeServoBusOptions(params);
  for (int id : params.servo_bus.state_ids) config.polled_ids.push_back(static_cast<uint8_t>(id));
  // Joint servos are polled too: their angles are the trajectories' measurements.
  for (int id : params.servo_bus.joint_ids) {
    const auto joint_id = static_cast<uint8_t>(id);
    if (std::find(config.polled_ids.begin(), config.polled_ids.end(), joint_id) ==
        config.polled_ids.end()) {
      config.polled_ids.push_back(joint_id);
    }
  }
  config.poll_rate = params.servo_bus.state_rate;
  config.relax_power_mw = static_cast<uint16_t>(params.servo_bus.relax_power_mw);
  // validate() accepted only the names shutdownActionFromString() knows.
  config.on_shutdown = device::shutdownActionFromString(params.servo_bus.on_shutdown)
                           .value_or(device::ShutdownAction::kStop);
  config.health_rate = params.servo_bus.health_rate;
  config.protect = params.servo_bus.protect;
  return config;
}

device::ServoBusEvents ServoBusInterface::makeEvents() {
  device::ServoBusEvents events;
  // On the bus worker thread.
  events.on_angle = [this](const device::ServoAngleSample& sample) {
    const sensor_msgs::JointState msg =
        busJointState(bus_joints_, sample.id, sample.angle_deg, toRosTime(sample.arrival));
    states_pub_.publish(msg);
    if (trajectory_) trajectory_->updateActual(msg);
  };
  events.on_servo_silent = [](uint8_t id, const device::ServoStatus& status,
                              std::chrono::milliseconds backoff) {
    ROS_WARN_THROTTLE(
        kWarnThrottleS, "servo_states: %s does not answer (%s); asked again in %.1f s",
        servoJointName(id).c_str(), status.message.c_str(), backoff.count() / kMsPerSecond);
  };
  events.on_overheat = [](const device::ServoHealthReport& report) {
    if (report.overheated) {
      ROS_ERROR("servo_bus: %s at %ld degC reached its over_temperature limit (%ld degC): relaxed, "
                "its moves refused until it has cooled %ld degC (~servo_bus/protect)",
                servoJointName(report.id).c_str(), static_cast<long>(report.readings.temperature_c),
                static_cast<long>(report.limits.over_temperature_c),
                static_cast<long>(device::OverheatGuard::kCoolDownC));
    } else {
      ROS_INFO("servo_bus: %s has cooled to %ld degC: its moves are obeyed again",
               servoJointName(report.id).c_str(), static_cast<long>(report.readings.temperature_c));
    }
  };
  events.on_move_failed = [](const device::MoveRequest& move, const device::ServoStatus& status) {
    ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands: %s not sent: %s",
                      servoJointName(move.id).c_str(), messageFor(status).c_str());
  };
  events.on_stop = [](uint8_t id, const device::ServoStatus& status) {
    if (status.ok()) {
      ROS_INFO("servo_bus: %s stopped: %s", servoJointName(id).c_str(), status.message.c_str());
    } else if (status.error == device::ServoError::kShutdown) {
      ROS_ERROR("servo_bus: %s", status.message.c_str());
    } else {
      ROS_WARN_THROTTLE(kWarnThrottleS,
                        "servo_bus: %s's stop not yet confirmed, writing it again: %s",
                        servoJointName(id).c_str(), status.message.c_str());
    }
  };
  return events;
}

ServoBusInterface::ServoBusInterface(ros::NodeHandle& nh, const DriverParams& params,
                                     device::SerialLink& link)
    : bus_joints_(makeBusJoints(params.servo_bus)),
      state_rate_(params.servo_bus.state_rate),
      link_(link),
      bus_(makeServoBusConfig(params), link.writer(), makeEvents()),
      client_(bus_.client()),
      nh_(nh),
      topics_nh_(nh),
      command_interval_ms_(static_cast<uint16_t>(params.servo_bus.command_interval_ms)) {
  // The bus's worker (the poll, the queued moves) runs on the port's reader thread: a poll writes
  // its request and reads the answer itself, with no second thread to wake per transaction.
  bus_.runOn(link_);

  // Own queue: a servo call waits on the bus (up to timeout * (retries + 1), or a whole motion with
  // wait = true) and must never hold up cmd_vel or joint_commands on the global queue.
  nh_.setCallbackQueue(&queue_);
  services_ = {
      advertiseServo<ServoPing>(
          nh_, "servo/ping",
          [this](ServoPing::Request& req, ServoPing::Response&) { return client_.ping(req.id); }),
      advertiseServo<ServoRead>(nh_, "servo/read",
                                [this](ServoRead::Request& req, ServoRead::Response& res) {
                                  device::ServoParamValue value;
                                  const device::ServoStatus status =
                                      client_.readParam(req.id, req.param, &value);
                                  if (status.ok()) {
                                    res.value = value.value;
                                    res.unit = value.unit;
                                  }
                                  return status;
                                }),
      advertiseServo<ServoWrite>(
          nh_, "servo/write",
          [this](ServoWrite::Request& req, ServoWrite::Response&) {
            return client_.writeParam(req.id, req.param, req.value);
          },
          Announce::kInfo),
      advertiseServo<ServoReadAngle>(
          nh_, "servo/read_angle",
          [this](ServoReadAngle::Request& req, ServoReadAngle::Response& res) {
            res.angle_deg = 0.0;
            res.turns = 0;
            if (req.multi_turn) {
              device::MultiTurnReading reading;
              const device::ServoStatus status = client_.readMultiTurnAngle(req.id, &reading);
              if (status.ok()) {
                res.angle_deg = reading.angle_deg;
                res.turns = reading.turns;
              }
              return status;
            }
            double angle_deg = 0.0;
            const device::ServoStatus status = client_.readAngle(req.id, &angle_deg);
            if (status.ok()) res.angle_deg = angle_deg;
            return status;
          }),
      advertiseServo<ServoMove>(nh_, "servo/move",
                                [this](ServoMove::Request& req, ServoMove::Response&) {
                                  device::MoveRequest request;
                                  request.id = req.id;
                                  request.angle_deg = req.angle_deg;
                                  request.multi_turn = req.multi_turn;
                                  request.interval_ms = req.interval_ms;
                                  request.velocity_dps = req.velocity_dps;
                                  request.accel_ms = req.accel_ms;
                                  request.decel_ms = req.decel_ms;
                                  request.power_mw = req.power_mw;
                                  device::ServoStatus refused = refuseWhileEStopped("servo/move");
                                  if (!refused.ok()) return refused;
                                  yieldJoint(req.id, "servo/move");
                                  return bus_.move(request);
                                }),
      advertiseServo<ServoScan>(nh_, "servo/scan",
                                [this](ServoScan::Request& req, ServoScan::Response& res) {
                                  return client_.scan(req.first_id, req.last_id, &res.ids);
                                }),
      advertiseServo<ServoRotate>(nh_, "servo/rotate",
                                  [this](ServoRotate::Request& req, ServoRotate::Response&) {
                                    device::RotateRequest request;
                                    request.id = req.id;
                                    request.angle_deg = req.angle_deg;
                                    request.interval_ms = req.interval_ms;
                                    request.power_mw = req.power_mw;
                                    request.wait = req.wait;
                                    device::ServoStatus refused =
                                        refuseWhileEStopped("servo/rotate");
                                    if (!refused.ok()) return refused;
                                    yieldJoint(req.id, "servo/rotate");
                                    return bus_.rotate(request);
                                  }),
      advertiseServo<ServoSpin>(nh_, "servo/spin",
                                [this](ServoSpin::Request& req, ServoSpin::Response&) {
                                  device::SpinRequest request;
                                  request.id = req.id;
                                  request.clockwise = req.clockwise;
                                  request.mode = req.mode;
                                  request.speed_dps = req.speed_dps;
                                  request.value = req.value;
                                  request.wait = req.wait;
                                  // A SPIN stop is no motion: it works while the e-stop holds.
                                  if (req.mode != 0) {
                                    device::ServoStatus refused = refuseWhileEStopped("servo/spin");
                                    if (!refused.ok()) return refused;
                                  }
                                  yieldJoint(req.id, "servo/spin");
                                  return bus_.spin(request);
                                }),
      advertiseServo<ServoDamping>(nh_, "servo/damping",
                                   [this](ServoDamping::Request& req, ServoDamping::Response&) {
                                     device::ServoStatus refused =
                                         refuseWhileEStopped("servo/damping");
                                     if (!refused.ok()) return refused;
                                     yieldJoint(req.id, "servo/damping");
                                     return bus_.damping(req.id, req.power_mw, req.wait);
                                   }),
      advertiseServo<ServoRelax>(nh_, "servo/relax",
                                 [this](ServoRelax::Request& req, ServoRelax::Response&) {
                                   device::ServoStatus refused = refuseWhileEStopped("servo/relax");
                                   if (!refused.ok()) return refused;
                                   yieldJoints(req.ids, "servo/relax");
                                   return bus_.relax(req.ids);
                                 }),
      advertiseServo<ServoHold>(nh_, "servo/hold",
                                [this](ServoHold::Request& req, ServoHold::Response&) {
                                  device::ServoStatus refused = refuseWhileEStopped("servo/hold");
                                  if (!refused.ok()) return refused;
                                  yieldJoints(req.ids, "servo/hold");
                                  return bus_.hold(req.ids);
                                }),
      advertiseServo<ServoReadAll>(nh_, "servo/read_all",
                                   [this](ServoReadAll::Request& req, ServoReadAll::Response& res) {
                                     std::vector<device::ServoParamValue> values;
                                     const device::ServoStatus status =
                                         client_.readAll(req.id, &values);
                                     res.names.clear();
                                     res.values.clear();
                                     for (const device::ServoParamValue& value : values) {
                                       res.names.push_back(value.name);
                                       res.values.push_back(value.value);
                                     }
                                     return status;
                                   }),
      advertiseServo<ServoResetUserData>(
          nh_, "servo/reset_user_data",
          [this](ServoResetUserData::Request& req, ServoResetUserData::Response&) {
            return client_.resetUserData(req.id);
          },
          Announce::kInfo),
  };

  if (params.servo_bus.allow_dangerous_writes) {
    ROS_WARN(
        "servo_bus: dangerous writes (servo_id, baudrate, response_switch, reserved cells, "
        "reset_user_data) are ARMED");
  }

  states_pub_ = topics_nh_.advertise<sensor_msgs::JointState>("servo_states", 10);
  commands_sub_ = topics_nh_.subscribe("servo_commands", 10, &ServoBusInterface::onServoCommands,
                                       this, ros::TransportHints().tcpNoDelay());
}

void ServoBusInterface::retune(const DriverParams& params) {
  bus_.retune(makeServoBusConfig(params));
  command_interval_ms_.store(static_cast<uint16_t>(params.servo_bus.command_interval_ms));
  // The joints' measurements come as often as the poll: their freshness limit follows it.
  if (trajectory_ && !bus_joints_.empty()) {
    std::vector<std::string> names;
    for (const trajectory::BusJoint& joint : bus_joints_) names.push_back(joint.name);
    trajectory_->setStateTimeout(names, busStateTimeout(params.servo_bus.state_rate));
  }
}

void ServoBusInterface::onServoCommands(const sensor_msgs::JointState::ConstPtr& msg) {
  if (!refuseWhileEStopped("servo_commands").ok()) {
    ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands refused, nothing sent: e_stop is engaged");
    return;
  }
  const ServoCommandBatch batch = toServoMoves(*msg, command_interval_ms_.load());
  if (!batch.error.empty()) {
    commands_rejected_.fetch_add(1);
    ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands rejected, nothing sent: the message %s",
                      batch.error.c_str());
    return;
  }
  // A joint servo under a trajectory is taken over by this command, and its goal aborted.
  std::vector<std::string> joints;
  for (const device::MoveRequest& move : batch.moves) {
    if (const trajectory::BusJoint* joint = findBusJoint(bus_joints_, move.id)) {
      joints.push_back(joint->name);
    }
  }
  const auto queue = [&] {
    bus_.queueMoves(batch.moves);
    return true;
  };
  if (trajectory_ && !joints.empty()) {
    trajectory_->takeOver(joints, "servo_commands", queue);
  } else {
    queue();
  }
}

device::ServoStatus ServoBusInterface::refuseWhileEStopped(const std::string& source) {
  if (!e_stop_ || !e_stop_->refuse(source)) return {};
  return {device::ServoError::kMotionRefused,
          "e_stop is engaged: no servo moves until it is released (publish false on e_stop)"};
}

void ServoBusInterface::attachEStop(device::EStop& e_stop) {
  e_stop_ = &e_stop;
  // On the e_stop subscriber's thread: the SPIN stops take the bus as a caller, ahead of the poll.
  // On the e_stop subscriber's thread, and it never waits for the bus: the gate is locked (no
  // motion frame from now on) and the stops are handed to the bus's worker, which writes them
  // ahead of everything else and keeps writing them until each servo is seen at rest.
  e_stop.addListener([this](bool engaged) {
    bus_.setMotionLocked(engaged);
    const std::vector<uint8_t> commanded = bus_.commandedIds();
    if (engaged && !commanded.empty()) {
      std::string ids;
      for (uint8_t id : commanded) ids += (ids.empty() ? "" : ", ") + std::to_string(id);
      ROS_WARN(
          "e_stop: stopping bus servo(s) %s (each stop is written until the servo is seen at "
          "rest)",
          ids.c_str());
    }
  });
}

void ServoBusInterface::yieldJoints(const std::vector<uint8_t>& ids, const char* source) {
  for (uint8_t id : ids.empty() ? bus_.config().polled_ids : ids) yieldJoint(id, source);
}

void ServoBusInterface::yieldJoint(uint8_t id, const char* source) {
  const trajectory::BusJoint* joint = findBusJoint(bus_joints_, id);
  if (!trajectory_ || !joint) return;
  trajectory_->takeOver({joint->name}, source, [&] {
    // A trajectory move still queued must not follow the service's command.
    bus_.dropQueuedMoves(id);
    return true;
  });
}

std::vector<TrajectoryJoints> ServoBusInterface::trajectoryJoints() {
  const auto queue_move = [this](uint8_t id, double angle_deg, uint32_t interval_ms) {
    device::MoveRequest move;
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

void ServoBusInterface::start() {
  if (spinner_ || shut_down_) return;
  // Two threads: one call waits on the bus while another is accepted and queued behind the bus
  // mutex, so ROS never sees the service as unresponsive. Idle, they sleep (no 10 Hz polling).
  spinner_ = std::make_unique<QueueSpinner>(&queue_, kSpinnerThreads);
  spinner_->start();
  bus_.start();
}

ServoBusInterface::~ServoBusInterface() { shutdown(); }

void ServoBusInterface::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  commands_sub_.shutdown();
  bus_.shutdown();  // fails a call waiting on the bus, so the spinner can stop quickly
  for (ros::ServiceServer& service : services_) service.shutdown();
  if (spinner_) spinner_->stop();
}

}  // namespace serial_robot_driver::ros_layer
