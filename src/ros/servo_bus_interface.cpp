#include "serial_robot_driver/ros/servo_bus_interface.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
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
// A servo that stops answering the poll is asked again after a back-off that doubles up to the
// maximum, so a dead servo costs one timeout per back-off period, not one per poll.
constexpr std::chrono::milliseconds kFirstBackoff{500};
constexpr std::chrono::milliseconds kMaxBackoff{8000};

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

ServoBusInterface::ServoBusInterface(ros::NodeHandle& nh, const DriverParams& params,
                                     device::SerialLink& link,
                                     diagnostic_updater::Updater& diagnostics)
    : link_(link),
      client_(makeServoBusOptions(params), link.writer()),
      diagnostics_(diagnostics),
      nh_(nh),
      topics_nh_(nh),
      poll_period_(1.0 / params.servo_bus.state_rate),
      command_interval_ms_(static_cast<uint16_t>(params.servo_bus.command_interval_ms)) {
  link_.addListener(&client_);

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
                                  yieldJoint(req.id, "servo/move");
                                  return client_.move(request);
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
                                    yieldJoint(req.id, "servo/rotate");
                                    return client_.rotate(request);
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
                                  yieldJoint(req.id, "servo/spin");
                                  return client_.spin(request);
                                }),
      advertiseServo<ServoDamping>(nh_, "servo/damping",
                                   [this](ServoDamping::Request& req, ServoDamping::Response&) {
                                     yieldJoint(req.id, "servo/damping");
                                     return client_.damping(req.id, req.power_mw, req.wait);
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

  diagnostics_.add("servo_bus", this, &ServoBusInterface::diagnose);

  if (params.servo_bus.allow_dangerous_writes) {
    ROS_WARN(
        "servo_bus: dangerous writes (servo_id, baudrate, response_switch, reserved cells, "
        "reset_user_data) are ARMED");
  }

  const auto now = device::Clock::now();
  for (int id : params.servo_bus.state_ids) {
    PolledServo servo;
    servo.id = static_cast<uint8_t>(id);
    servo.next_poll = now;
    polled_.push_back(servo);
  }
  // Joint servos are polled too: their angles are the trajectories' measurements.
  bus_joints_ = makeBusJoints(params.servo_bus);
  state_rate_ = params.servo_bus.state_rate;
  for (const trajectory::BusJoint& joint : bus_joints_) {
    const bool polled = std::any_of(polled_.begin(), polled_.end(),
                                    [&](const PolledServo& s) { return s.id == joint.id; });
    if (polled) continue;
    PolledServo servo;
    servo.id = joint.id;
    servo.next_poll = now;
    polled_.push_back(servo);
  }
  states_pub_ = topics_nh_.advertise<sensor_msgs::JointState>("servo_states", 10);
  commands_sub_ = topics_nh_.subscribe("servo_commands", 10, &ServoBusInterface::onServoCommands,
                                       this, ros::TransportHints().tcpNoDelay());
}

void ServoBusInterface::onServoCommands(const sensor_msgs::JointState::ConstPtr& msg) {
  ServoCommandBatch batch = toServoMoves(*msg, command_interval_ms_);
  const auto queueBatch = [&] {
    std::lock_guard<std::mutex> lock(worker_mutex_);
    if (!batch.error.empty()) {
      ++commands_rejected_;
      ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands rejected, nothing sent: the message %s",
                        batch.error.c_str());
      return false;
    }
    for (const device::MoveRequest& move : batch.moves) queueMoveLocked(move);
    return true;
  };
  // A joint servo under a trajectory is taken over by this command, and its goal aborted.
  std::vector<std::string> joints;
  for (const device::MoveRequest& move : batch.moves) {
    if (const trajectory::BusJoint* joint = findBusJoint(bus_joints_, move.id)) {
      joints.push_back(joint->name);
    }
  }
  if (trajectory_ && !joints.empty()) {
    trajectory_->takeOver(joints, "servo_commands", queueBatch);
  } else {
    queueBatch();
  }
}

void ServoBusInterface::queueMoveLocked(const device::MoveRequest& move) {
  // The latest target of a servo replaces a queued one: the queue stays bounded (one entry per
  // servo) when a long service call holds the bus.
  auto queued = std::find_if(queued_moves_.begin(), queued_moves_.end(),
                             [&move](const device::MoveRequest& m) { return m.id == move.id; });
  if (queued != queued_moves_.end()) {
    *queued = move;
  } else {
    queued_moves_.push_back(move);
  }
  worker_cv_.notify_all();
}

void ServoBusInterface::yieldJoint(uint8_t id, const char* source) {
  const trajectory::BusJoint* joint = findBusJoint(bus_joints_, id);
  if (!trajectory_ || !joint) return;
  trajectory_->takeOver({joint->name}, source, [&] {
    // A trajectory move still queued must not follow the service's command.
    std::lock_guard<std::mutex> lock(worker_mutex_);
    queued_moves_.erase(std::remove_if(queued_moves_.begin(), queued_moves_.end(),
                                       [id](const device::MoveRequest& m) { return m.id == id; }),
                        queued_moves_.end());
    return true;
  });
}

std::vector<TrajectoryJoints> ServoBusInterface::trajectoryJoints() {
  const auto queue_move = [this](uint8_t id, double angle_deg, uint32_t interval_ms) {
    device::MoveRequest move;
    move.id = id;
    move.angle_deg = angle_deg;
    move.interval_ms = interval_ms;
    std::lock_guard<std::mutex> lock(worker_mutex_);
    queueMoveLocked(move);
    return std::string();
  };
  return {busTrajectoryJoints(bus_joints_, queue_move, state_rate_)};
}

void ServoBusInterface::workerLoop() {
  std::unique_lock<std::mutex> lock(worker_mutex_);
  while (!worker_stop_) {
    if (!queued_moves_.empty()) {
      const device::MoveRequest move = queued_moves_.front();
      queued_moves_.pop_front();
      lock.unlock();
      const device::ServoStatus status = client_.move(move);
      if (!status.ok()) {
        ROS_WARN_THROTTLE(kWarnThrottleS, "servo_commands: %s not sent: %s",
                          servoJointName(move.id).c_str(), messageFor(status).c_str());
      }
      lock.lock();
      if (status.ok()) {
        ++commands_sent_;
      } else {
        ++command_failures_;
      }
      continue;
    }
    // The servo whose poll is due first.
    auto due = std::min_element(
        polled_.begin(), polled_.end(),
        [](const PolledServo& a, const PolledServo& b) { return a.next_poll < b.next_poll; });
    if (due == polled_.end()) {
      worker_cv_.wait(lock, [this] { return worker_stop_ || !queued_moves_.empty(); });
      continue;
    }
    if (device::Clock::now() < due->next_poll) {
      worker_cv_.wait_until(lock, due->next_poll);
      continue;
    }
    PolledServo& servo = *due;
    lock.unlock();
    pollOnce(servo);  // polled_ is only changed by this thread; the counters under the lock
    lock.lock();
  }
}

void ServoBusInterface::pollOnce(PolledServo& servo) {
  double angle_deg = 0.0;
  device::Clock::time_point arrival;
  const device::ServoStatus status = client_.pollAngle(servo.id, &angle_deg, &arrival);
  const auto now = device::Clock::now();
  const auto period = std::chrono::duration_cast<device::Clock::duration>(poll_period_);
  std::lock_guard<std::mutex> lock(worker_mutex_);
  if (status.error == device::ServoError::kNotConnected) {
    // The port is down, not the servo: ask again at the poll rate once it is back.
    servo.next_poll = now + period;
    return;
  }
  if (!status.ok()) {
    ++servo.failures;
    const bool was_online = servo.backoff.count() == 0;
    servo.backoff = was_online ? kFirstBackoff : std::min(servo.backoff * 2, kMaxBackoff);
    servo.next_poll = now + servo.backoff;
    if (was_online) {
      ROS_WARN_THROTTLE(kWarnThrottleS,
                        "servo_states: %s does not answer (%s); asked again in %.1f s",
                        servoJointName(servo.id).c_str(), status.message.c_str(),
                        servo.backoff.count() / kMsPerSecond);
    }
    return;
  }
  servo.backoff = std::chrono::milliseconds(0);
  // Keep the rate without drifting; after a stall, start again from now.
  servo.next_poll = std::max(servo.next_poll + period, now);
  const sensor_msgs::JointState msg =
      busJointState(bus_joints_, servo.id, angle_deg, toRosTime(arrival));
  states_pub_.publish(msg);
  if (trajectory_) trajectory_->updateActual(msg);
  ++states_published_;
}

void ServoBusInterface::start() {
  if (spinner_ || shut_down_) return;
  // Two threads: one call waits on the bus while another is accepted and queued behind the bus
  // mutex, so ROS never sees the service as unresponsive. Idle, they sleep (no 10 Hz polling).
  spinner_ = std::make_unique<QueueSpinner>(&queue_, kSpinnerThreads);
  spinner_->start();
  worker_ = std::thread([this] { workerLoop(); });
}

ServoBusInterface::~ServoBusInterface() { shutdown(); }

void ServoBusInterface::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  client_.shutdown();  // wakes a call waiting on the bus, so the spinner can stop quickly
  commands_sub_.shutdown();
  {
    std::lock_guard<std::mutex> lock(worker_mutex_);
    worker_stop_ = true;
  }
  worker_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  for (ros::ServiceServer& service : services_) service.shutdown();
  if (spinner_) spinner_->stop();
  diagnostics_.removeByName("servo_bus");
}

void ServoBusInterface::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const device::ServoBusStats stats = client_.stats();
  if (link_.connected()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   std::to_string(stats.transactions) + " transactions, " +
                       std::to_string(stats.timeouts) + " timeouts");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "servo bus port is not connected");
  }
  status.hardware_id = link_.options().path;
  status.add("port", link_.options().path);
  status.add("connected", link_.connected());
  status.add("transactions", stats.transactions);
  status.add("commands without answer", stats.commands);
  status.add("timeouts", stats.timeouts);
  status.add("retries", stats.retries);
  status.add("mismatched answers", stats.mismatched);
  status.add("garbled answers", stats.garbled);
  status.add("echoes skipped", stats.echoes);
  status.addf("last latency (ms)", "%.2f", stats.last_latency_ms);
  status.addf("max latency (ms)", "%.2f", stats.max_latency_ms);
  status.add("timeout (ms)", static_cast<int>(client_.options().timeout.count()));
  status.add("retries per transaction", client_.options().retries);
  status.add("dangerous writes armed", client_.options().allow_dangerous_writes);

  std::lock_guard<std::mutex> lock(worker_mutex_);
  std::string offline;
  for (const PolledServo& servo : polled_) {
    if (servo.backoff.count() > 0)
      offline += (offline.empty() ? "" : ", ") + std::to_string(servo.id);
  }
  status.add("servo_states published", states_published_);
  status.add("polled servos offline", offline.empty() ? std::string("none") : offline);
  status.add("servo_commands moves sent", commands_sent_);
  status.add("servo_commands rejected", commands_rejected_);
  status.add("servo_commands moves failed", command_failures_);
  if (!offline.empty() && link_.connected()) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN,
                        "polled servos not answering: " + offline);
  }
}

}  // namespace serial_robot_driver::ros_layer
