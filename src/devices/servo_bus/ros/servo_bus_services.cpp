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

// The outcome fields every servo/* response has; servo/ping calls its flag `online`.
template <typename Response>
void setOutcome(Response& res, const ServoReply& reply) {
  res.success = reply.ok;
  res.message = reply.message;
}
void setOutcome(ServoPing::Response& res, const ServoReply& reply) {
  res.online = reply.ok;
  res.message = reply.message;
}
// servo/scan has no flag: the ids it found are the outcome.
void setOutcome(ServoScan::Response& res, const ServoReply& reply) { res.message = reply.message; }

/// The core call behind one service (ServoServices): it copies the request's fields in and the
/// reply's own fields (values, angle) out; the outcome fields are filled by advertiseServo().
template <typename Service>
using ServoCall =
    std::function<ServoReply(typename Service::Request&, typename Service::Response&)>;

/// Advertises the servo/* service `name` on `nh` from its call. The service never throws through
/// to its caller (guardedService, counted in `refusals`) and always returns true, so the caller
/// gets the message instead of a bare "service call failed".
template <typename Service>
::ros::ServiceServer advertiseServo(::ros::NodeHandle& nh, core::InputRefusals& refusals,
                                    const std::string& name, ServoCall<Service> call) {
  using Request = typename Service::Request;
  using Response = typename Service::Response;
  const boost::function<bool(Request&, Response&)> serve = [call](Request& req, Response& res) {
    setOutcome(res, call(req, res));
    return true;
  };
  return nh.advertiseService<Request, Response>(
      name, ros_layer::guardedService<Request, Response>(refusals, name, serve));
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

RotateRequest toRotateRequest(const ServoRotate::Request& req) {
  RotateRequest request;
  request.id = req.id;
  request.angle_deg = req.angle_deg;
  request.interval_ms = req.interval_ms;
  request.power_mw = req.power_mw;
  request.wait = req.wait;
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
    : client_(bus.client()),
      refusals_(refusals),
      handlers_(bus, claims, refusals),
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
  namespace name = servo_service;
  services_.push_back(advertiseServo<ServoPing>(
      nh_, refusals_, name::kPing,
      [this](ServoPing::Request& req, ServoPing::Response&) { return handlers_.ping(req.id); }));
  services_.push_back(advertiseServo<ServoRead>(
      nh_, refusals_, name::kRead, [this](ServoRead::Request& req, ServoRead::Response& res) {
        const ServoReadReply reply = handlers_.read(req.id, req.param);
        res.value = reply.value;
        res.unit = reply.unit;
        return reply;
      }));
  services_.push_back(advertiseServo<ServoReadAngle>(
      nh_, refusals_, name::kReadAngle,
      [this](ServoReadAngle::Request& req, ServoReadAngle::Response& res) {
        const ServoAngleReply reply = handlers_.readAngle(req.id, req.multi_turn);
        res.angle_deg = reply.angle_deg;
        res.turns = reply.turns;
        return reply;
      }));
  services_.push_back(advertiseServo<ServoScan>(
      nh_, refusals_, name::kScan, [this](ServoScan::Request& req, ServoScan::Response& res) {
        const ServoScanReply reply = handlers_.scan(req.first_id, req.last_id);
        res.ids = reply.ids;
        return reply;
      }));
  services_.push_back(
      advertiseServo<ServoReadAll>(nh_, refusals_, name::kReadAll,
                                   [this](ServoReadAll::Request& req, ServoReadAll::Response& res) {
                                     const ServoReadAllReply reply = handlers_.readAll(req.id);
                                     res.names = reply.names;
                                     res.values = reply.values;
                                     return reply;
                                   }));
  services_.push_back(advertiseServo<ServoInfo>(
      nh_, refusals_, name::kInfo, [this](ServoInfo::Request& req, ServoInfo::Response& res) {
        const ServoInfoReply reply = handlers_.info(req.id);
        res.servo_type = reply.identity.servo_type;
        res.firmware_version = reply.identity.firmware_version;
        res.serial_number = reply.identity.serial_number;
        res.response_switch = reply.identity.response_switch;
        return reply;
      }));
}

void ServoBusServices::advertiseWrites() {
  namespace name = servo_service;
  services_.push_back(advertiseServo<ServoWrite>(
      nh_, refusals_, name::kWrite, [this](ServoWrite::Request& req, ServoWrite::Response&) {
        return handlers_.write(req.id, req.param, req.value);
      }));
  services_.push_back(advertiseServo<ServoResetUserData>(
      nh_, refusals_, name::kResetUserData,
      [this](ServoResetUserData::Request& req, ServoResetUserData::Response&) {
        return handlers_.resetUserData(req.id);
      }));
}

void ServoBusServices::advertiseMoves() {
  namespace name = servo_service;
  services_.push_back(advertiseServo<ServoMove>(
      nh_, refusals_, name::kMove, [this](ServoMove::Request& req, ServoMove::Response&) {
        return handlers_.move(toMoveRequest(req));
      }));
  services_.push_back(advertiseServo<ServoRotate>(
      nh_, refusals_, name::kRotate, [this](ServoRotate::Request& req, ServoRotate::Response&) {
        return handlers_.rotate(toRotateRequest(req));
      }));
}

void ServoBusServices::advertiseStops() {
  namespace name = servo_service;
  services_.push_back(advertiseServo<ServoSpin>(
      stop_nh_, refusals_, name::kSpin, [this](ServoSpin::Request& req, ServoSpin::Response&) {
        return handlers_.spin(toSpinRequest(req));
      }));
  services_.push_back(
      advertiseServo<ServoDamping>(stop_nh_, refusals_, name::kDamping,
                                   [this](ServoDamping::Request& req, ServoDamping::Response&) {
                                     return handlers_.damping(req.id, req.power_mw, req.wait);
                                   }));
  services_.push_back(advertiseServo<ServoRelax>(
      stop_nh_, refusals_, name::kRelax, [this](ServoRelax::Request& req, ServoRelax::Response&) {
        return handlers_.relax(req.ids);
      }));
  services_.push_back(advertiseServo<ServoHold>(
      stop_nh_, refusals_, name::kHold,
      [this](ServoHold::Request& req, ServoHold::Response&) { return handlers_.hold(req.ids); }));
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
