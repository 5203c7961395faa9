#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_services.h"

#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/ros/servo_bus_ros.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::devices::servo_bus::ros {

namespace {

constexpr int kSpinnerThreads = 2;
constexpr int kStopSpinnerThreads = 1;

void logOutcome(const std::string& service, const ServoStatus& status) {
  if (status.ok()) {
    ROS_DEBUG("%s: %s", service.c_str(), status.message.c_str());
  } else {
    ROS_DEBUG("%s failed (%s): %s", service.c_str(), toString(status.error),
              status.message.c_str());
  }
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
    std::function<ServoStatus(typename Service::Request&, typename Service::Response&)>;

/// The node handle the servo/* services are advertised on, and where their refusals are counted.
struct ServoServiceSite {
  ::ros::NodeHandle& nh;
  core::InputRefusals& refusals;
};

/// Advertises one servo/* service from its call. The service logs the outcome, never throws
/// through to its caller (guardedService) and always returns true, so the caller gets the message
/// instead of a bare "service call failed".
template <typename Service>
::ros::ServiceServer advertiseServo(ServoServiceSite site, const std::string& name,
                                    ServoCall<Service> call, Announce announce = Announce::kDebug) {
  using Request = typename Service::Request;
  using Response = typename Service::Response;
  core::InputRefusals& refusals = site.refusals;
  const boost::function<bool(Request&, Response&)> serve = [name, call, announce, &refusals](
                                                               Request& req, Response& res) {
    const ServoStatus status = call(req, res);
    logOutcome(name, status);
    if (refusesRequest(status.error)) refusals.refused(name);
    if (status.ok() && announce == Announce::kInfo) {
      ROS_INFO("%s: %s", name.c_str(), status.message.c_str());
    }
    setOutcome(res, status.ok(), servoStatusMessage(status));
    return true;
  };
  return site.nh.advertiseService<Request, Response>(
      name, ros_layer::guardedService<Request, Response>(refusals, name, serve));
}

ServoStatus readAngle(ServoBusClient& client, const ServoReadAngle::Request& req,
                      ServoReadAngle::Response& res) {
  res.angle_deg = 0.0;
  res.turns = 0;
  if (req.multi_turn) {
    MultiTurnReading reading;
    const ServoStatus status = client.readMultiTurnAngle(req.id, &reading);
    if (status.ok()) {
      res.angle_deg = reading.angle_deg;
      res.turns = reading.turns;
    }
    return status;
  }
  double angle_deg = 0.0;
  const ServoStatus status = client.readAngle(req.id, &angle_deg);
  if (status.ok()) res.angle_deg = angle_deg;
  return status;
}

ServoStatus readAll(ServoBusClient& client, const ServoReadAll::Request& req,
                    ServoReadAll::Response& res) {
  std::vector<ServoParamValue> values;
  const ServoStatus status = client.readAll(req.id, &values);
  res.names.clear();
  res.values.clear();
  for (const ServoParamValue& value : values) {
    res.names.push_back(value.name);
    res.values.push_back(value.value);
  }
  return status;
}

ServoStatus readInfo(ServoBusClient& client, const ServoIdentityChecks& expected,
                     const ServoInfo::Request& req, ServoInfo::Response& res) {
  ServoIdentity identity;
  const ServoStatus status = readServoInfo(client, req.id, expected, &identity);
  res.servo_type = identity.servo_type;
  res.firmware_version = identity.firmware_version;
  res.serial_number = identity.serial_number;
  res.response_switch = identity.response_switch;
  return status;
}

MoveRequest toMoveRequest(const ServoMove::Request& req) {
  MoveRequest request;
  request.id = req.id;
  request.angle_deg = req.angle_deg;
  request.multi_turn = req.multi_turn;
  request.interval_ms = req.interval_ms;
  request.velocity_dps = req.velocity_dps;
  request.accel_ms = req.accel_ms;
  request.decel_ms = req.decel_ms;
  request.power_mw = req.power_mw;
  return request;
}

SpinRequest toSpinRequest(const ServoSpin::Request& req) {
  SpinRequest request;
  request.id = req.id;
  request.clockwise = req.clockwise;
  request.mode = req.mode;
  request.speed_dps = req.speed_dps;
  request.value = req.value;
  request.wait = req.wait;
  return request;
}

}  // namespace

ServoBusServices::ServoBusServices(::ros::NodeHandle& nh, ServoBus& bus, ServoMotionClaims& claims,
                                   core::InputRefusals& refusals)
    : bus_(bus),
      client_(bus.client()),
      claims_(claims),
      refusals_(refusals),
      nh_(nh),
      stop_queue_([this] { client_.stopCallQueued(); }),
      stop_nh_(nh) {
  // Own queues: a servo call waits on the bus (up to timeout * (retries + 1), or a whole motion
  // with wait = true) and must never hold up cmd_vel or joint_commands on the global queue; a stop
  // must never wait behind such a call (see the threading model in servo_bus_ros.h).
  nh_.setCallbackQueue(&queue_);
  stop_nh_.setCallbackQueue(&stop_queue_);
  client_.setStopCallsQueued([this] { return stop_queue_.waiting(); });
  advertiseReads();
  advertiseWrites();
  advertiseMoves();
  advertiseStops();
}

ServoBusServices::~ServoBusServices() { shutdown(); }

void ServoBusServices::start() {
  if (spinner_ || shut_down_) return;
  // The stop services' thread first: from the first call on, a stop never waits behind another.
  stop_spinner_ = std::make_unique<ros_layer::QueueSpinner>(&stop_queue_, kStopSpinnerThreads);
  stop_spinner_->start();
  // Two threads: one call waits on the bus while another is accepted and queued behind the bus
  // mutex, so ROS never sees the service as unresponsive. Idle, they sleep (no 10 Hz polling).
  spinner_ = std::make_unique<ros_layer::QueueSpinner>(&queue_, kSpinnerThreads);
  spinner_->start();
}

void ServoBusServices::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  for (::ros::ServiceServer& service : services_) service.shutdown();
  if (spinner_) spinner_->stop();
  if (stop_spinner_) stop_spinner_->stop();
}

void ServoBusServices::advertiseReads() {
  const ServoServiceSite site{nh_, refusals_};
  services_.push_back(advertiseServo<ServoPing>(
      site, "servo/ping",
      [this](ServoPing::Request& req, ServoPing::Response&) { return client_.ping(req.id); }));
  services_.push_back(advertiseServo<ServoRead>(
      site, "servo/read", [this](ServoRead::Request& req, ServoRead::Response& res) {
        ServoParamValue value;
        const ServoStatus status = client_.readParam(req.id, req.param, &value);
        if (status.ok()) {
          res.value = value.value;
          res.unit = value.unit;
        }
        return status;
      }));
  services_.push_back(advertiseServo<ServoReadAngle>(
      site, "servo/read_angle",
      [this](ServoReadAngle::Request& req, ServoReadAngle::Response& res) {
        return readAngle(client_, req, res);
      }));
  services_.push_back(advertiseServo<ServoScan>(
      site, "servo/scan", [this](ServoScan::Request& req, ServoScan::Response& res) {
        return client_.scan(req.first_id, req.last_id, &res.ids);
      }));
  services_.push_back(advertiseServo<ServoReadAll>(
      site, "servo/read_all", [this](ServoReadAll::Request& req, ServoReadAll::Response& res) {
        return readAll(client_, req, res);
      }));
  services_.push_back(advertiseServo<ServoInfo>(
      site, "servo/info", [this](ServoInfo::Request& req, ServoInfo::Response& res) {
        return readInfo(client_, bus_.config().identity, req, res);
      }));
}

void ServoBusServices::advertiseWrites() {
  const ServoServiceSite site{nh_, refusals_};
  services_.push_back(advertiseServo<ServoWrite>(
      site, "servo/write",
      [this](ServoWrite::Request& req, ServoWrite::Response&) {
        return bus_.writeParam(req.id, req.param, req.value);
      },
      Announce::kInfo));
  services_.push_back(advertiseServo<ServoResetUserData>(
      site, "servo/reset_user_data",
      [this](ServoResetUserData::Request& req, ServoResetUserData::Response&) {
        return bus_.resetUserData(req.id);
      },
      Announce::kInfo));
}

void ServoBusServices::advertiseMoves() {
  const ServoServiceSite site{nh_, refusals_};
  services_.push_back(advertiseServo<ServoMove>(
      site, "servo/move", [this](ServoMove::Request& req, ServoMove::Response&) {
        return claims_.move(toMoveRequest(req), "servo/move");
      }));
  services_.push_back(advertiseServo<ServoRotate>(
      site, "servo/rotate", [this](ServoRotate::Request& req, ServoRotate::Response&) {
        RotateRequest request;
        request.id = req.id;
        request.angle_deg = req.angle_deg;
        request.interval_ms = req.interval_ms;
        request.power_mw = req.power_mw;
        request.wait = req.wait;
        return claims_.rotate(request, "servo/rotate");
      }));
}

void ServoBusServices::advertiseStops() {
  const ServoServiceSite site{stop_nh_, refusals_};
  services_.push_back(advertiseServo<ServoSpin>(
      site, "servo/spin", [this](ServoSpin::Request& req, ServoSpin::Response&) {
        return claims_.spin(toSpinRequest(req), "servo/spin");
      }));
  services_.push_back(advertiseServo<ServoDamping>(
      site, "servo/damping", [this](ServoDamping::Request& req, ServoDamping::Response&) {
        return claims_.damping(req.id, req.power_mw, req.wait, "servo/damping");
      }));
  services_.push_back(advertiseServo<ServoRelax>(
      site, "servo/relax", [this](ServoRelax::Request& req, ServoRelax::Response&) {
        return claims_.relax(req.ids, "servo/relax");
      }));
  services_.push_back(advertiseServo<ServoHold>(
      site, "servo/hold", [this](ServoHold::Request& req, ServoHold::Response&) {
        return claims_.hold(req.ids, "servo/hold");
      }));
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
