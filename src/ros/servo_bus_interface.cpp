#include "serial_robot_driver/ros/servo_bus_interface.h"

#include <cmath>
#include <exception>
#include <string>
#include <utility>

namespace serial_robot_driver::ros_layer {

namespace {

constexpr int kSpinnerThreads = 2;
constexpr double kMsPerSecond = 1000.0;

// Runs one service body. A service never throws through to its caller and always returns true, so
// the caller gets the message instead of a bare "service call failed".
template <typename Body, typename Fail>
bool serve(const char* service, Body&& body, Fail&& fail) {
  try {
    body();
  } catch (const std::exception& error) {
    ROS_ERROR("%s: internal error: %s", service, error.what());
    fail(std::string("internal error: ") + error.what());
  }
  return true;
}

void logOutcome(const char* service, const device::ServoStatus& status) {
  if (status.ok()) {
    ROS_DEBUG("%s: %s", service, status.message.c_str());
  } else {
    ROS_DEBUG("%s failed (%s): %s", service, device::toString(status.error),
              status.message.c_str());
  }
}

/// The core says "dangerous"; only this layer knows which parameter arms such writes.
std::string messageFor(const device::ServoStatus& status) {
  if (status.error != device::ServoError::kDangerous) return status.message;
  return status.message + " (set ~servo_bus/allow_dangerous_writes to true to arm it)";
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
      client_(makeServoBusOptions(params),
              [&link](const std::vector<uint8_t>& frame) { return link.write(frame); }),
      diagnostics_(diagnostics),
      nh_(nh) {
  link_.addListener(&client_);

  // Own queue: a servo call waits on the bus (up to timeout * (retries + 1), or a whole motion with
  // wait = true) and must never hold up cmd_vel or joint_commands on the global queue.
  nh_.setCallbackQueue(&queue_);
  services_.push_back(nh_.advertiseService("servo/ping", &ServoBusInterface::onPing, this));
  services_.push_back(nh_.advertiseService("servo/read", &ServoBusInterface::onRead, this));
  services_.push_back(nh_.advertiseService("servo/write", &ServoBusInterface::onWrite, this));
  services_.push_back(
      nh_.advertiseService("servo/read_angle", &ServoBusInterface::onReadAngle, this));
  services_.push_back(nh_.advertiseService("servo/rotate", &ServoBusInterface::onRotate, this));
  services_.push_back(nh_.advertiseService("servo/spin", &ServoBusInterface::onSpin, this));
  services_.push_back(nh_.advertiseService("servo/damping", &ServoBusInterface::onDamping, this));
  services_.push_back(nh_.advertiseService("servo/read_all", &ServoBusInterface::onReadAll, this));
  services_.push_back(
      nh_.advertiseService("servo/reset_user_data", &ServoBusInterface::onResetUserData, this));

  diagnostics_.add("serial_robot_driver: servo_bus", this, &ServoBusInterface::diagnose);

  if (params.servo_bus.allow_dangerous_writes) {
    ROS_WARN("servo_bus: dangerous writes (servo_id, baudrate, reset_user_data) are ARMED");
  }
  // Two threads: one call waits on the bus while another is accepted and queued behind the bus
  // mutex, so ROS never sees the service as unresponsive.
  spinner_ = std::make_unique<ros::AsyncSpinner>(kSpinnerThreads, &queue_);
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

bool ServoBusInterface::onPing(ServoPing::Request& req, ServoPing::Response& res) {
  return serve(
      "servo/ping",
      [&] {
        const device::ServoStatus status = client_.ping(req.id);
        logOutcome("servo/ping", status);
        res.online = status.ok();
        res.message = status.message;
      },
      [&](const std::string& message) {
        res.online = false;
        res.message = message;
      });
}

bool ServoBusInterface::onRead(ServoRead::Request& req, ServoRead::Response& res) {
  return serve(
      "servo/read",
      [&] {
        device::ServoParamValue value;
        const device::ServoStatus status = client_.readParam(req.id, req.param, &value);
        logOutcome("servo/read", status);
        res.success = status.ok();
        res.message = status.message;
        if (status.ok()) {
          res.value = value.value;
          res.unit = value.unit;
        }
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
}

bool ServoBusInterface::onWrite(ServoWrite::Request& req, ServoWrite::Response& res) {
  return serve(
      "servo/write",
      [&] {
        const device::ServoStatus status = client_.writeParam(req.id, req.param, req.value);
        logOutcome("servo/write", status);
        if (status.ok()) ROS_INFO("servo/write: %s", status.message.c_str());
        res.success = status.ok();
        res.message = messageFor(status);
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
}

bool ServoBusInterface::onReadAngle(ServoReadAngle::Request& req, ServoReadAngle::Response& res) {
  return serve(
      "servo/read_angle",
      [&] {
        double angle_deg = 0.0;
        const device::ServoStatus status = client_.readAngle(req.id, &angle_deg);
        logOutcome("servo/read_angle", status);
        res.success = status.ok();
        res.angle_deg = status.ok() ? angle_deg : 0.0;
        res.message = status.message;
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
}

bool ServoBusInterface::onRotate(ServoRotate::Request& req, ServoRotate::Response& res) {
  return serve(
      "servo/rotate",
      [&] {
        device::RotateRequest request;
        request.id = req.id;
        request.angle_deg = req.angle_deg;
        request.interval_ms = req.interval_ms;
        request.power_mw = req.power_mw;
        request.wait = req.wait;
        const device::ServoStatus status = client_.rotate(request);
        logOutcome("servo/rotate", status);
        res.success = status.ok();
        res.message = status.message;
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
}

bool ServoBusInterface::onSpin(ServoSpin::Request& req, ServoSpin::Response& res) {
  return serve(
      "servo/spin",
      [&] {
        device::SpinRequest request;
        request.id = req.id;
        request.clockwise = req.clockwise;
        request.mode = req.mode;
        request.speed_dps = req.speed_dps;
        request.value = req.value;
        request.wait = req.wait;
        const device::ServoStatus status = client_.spin(request);
        logOutcome("servo/spin", status);
        res.success = status.ok();
        res.message = status.message;
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
}

bool ServoBusInterface::onDamping(ServoDamping::Request& req, ServoDamping::Response& res) {
  return serve(
      "servo/damping",
      [&] {
        const device::ServoStatus status = client_.damping(req.id, req.power_mw, req.wait);
        logOutcome("servo/damping", status);
        res.success = status.ok();
        res.message = status.message;
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
}

bool ServoBusInterface::onReadAll(ServoReadAll::Request& req, ServoReadAll::Response& res) {
  return serve(
      "servo/read_all",
      [&] {
        std::vector<device::ServoParamValue> values;
        const device::ServoStatus status = client_.readAll(req.id, &values);
        logOutcome("servo/read_all", status);
        res.success = status.ok();
        res.message = status.message;
        res.names.clear();
        res.values.clear();
        for (const device::ServoParamValue& value : values) {
          res.names.push_back(value.name);
          res.values.push_back(value.value);
        }
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
        res.names.clear();
        res.values.clear();
      });
}

bool ServoBusInterface::onResetUserData(ServoResetUserData::Request& req,
                                        ServoResetUserData::Response& res) {
  return serve(
      "servo/reset_user_data",
      [&] {
        const device::ServoStatus status = client_.resetUserData(req.id);
        logOutcome("servo/reset_user_data", status);
        if (status.ok()) ROS_INFO("servo/reset_user_data: %s", status.message.c_str());
        res.success = status.ok();
        res.message = messageFor(status);
      },
      [&](const std::string& message) {
        res.success = false;
        res.message = message;
      });
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
