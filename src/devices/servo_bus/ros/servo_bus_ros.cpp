#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_ros.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/publish_wanted.h"

namespace serial_robot_driver::devices::servo_bus::ros {

namespace {

constexpr double kMsPerSecond = 1000.0;
constexpr double kWarnThrottleS = 5.0;

}  // namespace

/// The core says "dangerous"; only this layer knows which parameter arms such writes.
std::string servoStatusMessage(const ServoStatus& status) {
  if (status.error != ServoError::kDangerous) return status.message;
  return status.message + " (set ~servo_bus/allow_dangerous_writes to true to arm it)";
}

ServoCommandBatch toServoMoves(const sensor_msgs::JointState& msg, uint16_t interval_ms) {
  return servo_bus::toServoMoves(msg.name, msg.position, msg.velocity, interval_ms);
}

ServoBusConfig makeServoBusConfig(const ros_layer::DriverParams& params) {
  ServoBusConfig config = params.section(kServoBusSection).bus;
  for (int id : params.section(kServoBusSection).state_ids)
    config.polled_ids.push_back(static_cast<uint8_t>(id));
  // Joint servos are polled too: their angles are the trajectories' measurements.
  for (int id : params.section(kServoBusSection).joint_ids) {
    const auto joint_id = static_cast<uint8_t>(id);
    if (std::find(config.polled_ids.begin(), config.polled_ids.end(), joint_id) ==
        config.polled_ids.end()) {
      config.polled_ids.push_back(joint_id);
    }
  }
  for (int id : params.section(kServoBusSection).joint_ids) {
    config.identity.joint_ids.push_back(static_cast<uint8_t>(id));
  }
  return config;
}

ServoBusEvents ServoBusRos::makeEvents() {
  ServoBusEvents events;
  // On the bus worker thread.
  events.on_angle = [this](const ServoAngleSample& sample) {
    trajectory::TrajectoryExecutor* trajectories = claims_.trajectories();
    if (!trajectories && !ros_layer::wanted(states_pub_)) return;  // nobody asked for it
    const sensor_msgs::JointState msg = busJointState(bus_joints_, sample.id, sample.angle_deg,
                                                      ros_layer::toRosTime(sample.arrival));
    if (ros_layer::wanted(states_pub_)) states_pub_.publish(msg);
    if (trajectories) trajectories->updateActual(msg.name, msg.position, msg.velocity);
  };
  events.on_servo_silent = [](uint8_t id, const ServoStatus& status,
                              std::chrono::milliseconds backoff) {
    ROS_WARN_THROTTLE(
        kWarnThrottleS, "servo_states: %s does not answer (%s); asked again in %.1f s",
        servoJointName(id).c_str(), status.message.c_str(), backoff.count() / kMsPerSecond);
  };
  events.on_overheat = [](const ServoHealthReport& report) {
    if (report.overheated) {
      ROS_ERROR(
          "servo_bus: %s at %ld degC reached its over_temperature limit (%ld degC): relaxed, "
          "its moves refused until it has cooled %ld degC (~servo_bus/protect)",
          servoJointName(report.id).c_str(), static_cast<long>(report.readings.temperature_c),
          static_cast<long>(report.limits.over_temperature_c),
          static_cast<long>(OverheatGuard::kCoolDownC));
    } else {
      ROS_INFO("servo_bus: %s has cooled to %ld degC: its moves are obeyed again",
               servoJointName(report.id).c_str(), static_cast<long>(report.readings.temperature_c));
    }
  };
  // Once per servo, when it first answered: what it is, and what does not fit (once each).
  events.on_identity = [](const ServoIdentityReport& report) {
    ROS_INFO("servo_bus: %s: %s, angle limits %s", servoJointName(report.id).c_str(),
             describeIdentity(report.identity).c_str(),
             describeAngleLimits(report.identity).c_str());
    for (const std::string& warning : report.warnings) ROS_WARN("servo_bus: %s", warning.c_str());
  };
  events.on_move_failed = [](const MoveRequest& move, const ServoStatus& status) {
    ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands: %s not sent: %s",
                      servoJointName(move.id).c_str(), servoStatusMessage(status).c_str());
  };
  events.on_stop = [](uint8_t id, const ServoStatus& status) {
    if (status.ok()) {
      ROS_INFO("servo_bus: %s stopped: %s", servoJointName(id).c_str(), status.message.c_str());
    } else if (status.error == ServoError::kShutdown) {
      ROS_ERROR("servo_bus: %s", status.message.c_str());
    } else {
      ROS_WARN_THROTTLE(kWarnThrottleS,
                        "servo_bus: %s's stop not yet confirmed, writing it again: %s",
                        servoJointName(id).c_str(), status.message.c_str());
    }
  };
  return events;
}

ServoBusRos::ServoBusRos(::ros::NodeHandle& nh, const ros_layer::DriverParams& params,
                         core::SerialLink& link)
    : bus_joints_(makeBusJoints(params.section(kServoBusSection))),
      state_rate_(params.section(kServoBusSection).bus.poll_rate),
      link_(link),
      bus_(makeServoBusConfig(params), link.writer(), makeEvents()),
      claims_(bus_, bus_joints_),
      services_(nh, bus_, claims_, inputRefusals()),
      topics_nh_(nh),
      command_interval_ms_(
          static_cast<uint16_t>(params.section(kServoBusSection).command_interval_ms)),
      diagnostics_(bus_, link) {
  // The bus's worker (the poll, the queued moves) runs on the port's reader thread: a poll writes
  // its request and reads the answer itself, with no second thread to wake per transaction.
  bus_.runOn(link_);

  if (params.section(kServoBusSection).bus.client.allow_dangerous_writes) {
    ROS_WARN(
        "servo_bus: dangerous writes (servo_id, baudrate, response_switch, reserved cells, "
        "reset_user_data) are ARMED");
  }

  states_pub_ = topics_nh_.advertise<sensor_msgs::JointState>("servo_states", 10);
  commands_sub_ = ros_layer::subscribeGuarded(topics_nh_, inputRefusals(), "servo_commands", 10,
                                              &ServoBusRos::onServoCommands, this,
                                              ::ros::TransportHints().tcpNoDelay());
}

void ServoBusRos::retune(const ros_layer::DriverParams& params) {
  bus_.retune(makeServoBusConfig(params));
  command_interval_ms_.store(
      static_cast<uint16_t>(params.section(kServoBusSection).command_interval_ms));
  claims_.followPollRate(params.section(kServoBusSection).bus.poll_rate);
}

void ServoBusRos::onServoCommands(const sensor_msgs::JointState::ConstPtr& msg) {
  if (!claims_.refuseWhileEStopped("servo_commands").ok()) {
    ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands refused, nothing sent: e_stop is engaged");
    return;
  }
  const ServoCommandBatch batch = toServoMoves(*msg, command_interval_ms_.load());
  if (!batch.error.empty()) {
    commands_rejected_.fetch_add(1);
    inputRefusals().refused("servo_commands");
    ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands rejected, nothing sent: the message %s",
                      batch.error.c_str());
    return;
  }
  // A joint servo under a trajectory is taken over by this command, and its goal aborted.
  claims_.queueCommand(batch.moves, "servo_commands");
}

void ServoBusRos::attachEStop(core::EStop& e_stop) {
  claims_.attachEStop(e_stop);
  // On the e_stop subscriber's thread: the SPIN stops take the bus as a caller, ahead of the poll.
  // On the e_stop subscriber's thread, and it never waits for the bus: the gate is locked (no
  // motion frame from now on) and the stops are handed to the bus's worker, which writes them
  // ahead of everything else and keeps writing them until each servo is seen at rest.
  e_stop.addListener([this](bool engaged) {
    bus_.setMotionLocked(engaged);
    const std::vector<uint8_t> commanded = bus_.commandedIds();
    if (engaged && !commanded.empty()) {
      ROS_WARN(
          "e_stop: stopping bus servo(s) %s (each stop is written until the servo is seen at "
          "rest)",
          servoIdList(commanded).c_str());
    }
  });
}

std::vector<core::Device::NamedStatus> ServoBusRos::extraStatuses() {
  std::vector<NamedStatus> statuses;
  for (uint8_t id : bus_.config().polled_ids) {
    statuses.push_back({"servo_bus servo " + std::to_string(id),
                        [this, id] { return diagnostics_.servoStatus(id); }});
  }
  return statuses;
}

std::vector<ros_layer::TrajectoryJoints> ServoBusRos::trajectoryJoints() {
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

void ServoBusRos::start() {
  if (started_ || shut_down_) return;
  started_ = true;
  services_.start();
  bus_.start();
}

ServoBusRos::~ServoBusRos() { shutdown(); }

void ServoBusRos::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  commands_sub_.shutdown();
  bus_.shutdown();  // fails a call waiting on the bus, so the spinners can stop quickly
  services_.shutdown();
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
