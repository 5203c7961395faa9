#include "serial_robot_driver/ros/servo_bus_interface.h"

#include <cmath>
#include <exception>
#include <functional>
#include <string>
#include <utility>

namespace serial_robot_driver::ros_layer {

namespace {

constexpr int kSpinnerThreads = 2;
constexpr double kMsPerSecond = 1000.0;

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
      nh_(nh) {
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
            double angle_deg = 0.0;
            const device::ServoStatus status = client_.readAngle(req.id, &angle_deg);
            res.angle_deg = status.ok() ? angle_deg : 0.0;
            return status;
          }),
      advertiseServo<ServoRotate>(nh_, "servo/rotate",
                                  [this](ServoRotate::Request& req, ServoRotate::Response&) {
                                    device::RotateRequest request;
                                    request.id = req.id;
                                    request.angle_deg = req.angle_deg;
                                    request.interval_ms = req.interval_ms;
                                    request.power_mw = req.power_mw;
                                    request.wait = req.wait;
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
                                  return client_.spin(request);
                                }),
      advertiseServo<ServoDamping>(nh_, "servo/damping",
                                   [this](ServoDamping::Request& req, ServoDamping::Response&) {
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

  diagnostics_.add("serial_robot_driver: servo_bus", this, &ServoBusInterface::diagnose);

  if (params.servo_bus.allow_dangerous_writes) {
    ROS_WARN("servo_bus: dangerous writes (servo_id, baudrate, reset_user_data) are ARMED");
  }
}

void ServoBusInterface::start() {
  if (spinner_ || shut_down_) return;
  // Two threads: one call waits on the bus while another is accepted and queued behind the bus
  // mutex, so ROS never sees the service as unresponsive. Idle, they sleep (no 10 Hz polling).
  spinner_ = std::make_unique<QueueSpinner>(&queue_, kSpinnerThreads);
  spinner_->start();
}

ServoBusInterface::~ServoBusInterface() { shutdown(); }

void ServoBusInterface::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  client_.shutdown();  // wakes a call waiting on the bus, so the spinner can stop quickly
  for (ros::ServiceServer& service : services_) service.shutdown();
  if (spinner_) spinner_->stop();
  diagnostics_.removeByName("serial_robot_driver: servo_bus");
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
}

}  // namespace serial_robot_driver::ros_layer
