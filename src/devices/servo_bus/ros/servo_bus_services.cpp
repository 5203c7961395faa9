// The servo/* services: each one a client or bus call behind the same outcome handling (logged,
// never thrown through, the message always returned). Served from ServoBusInterface's own queues:
// the stop services (servo/spin, servo/relax, servo/damping, servo/hold) from the stop queue
// (stop_nh_), whose bus turns are urgent work, every other from the second one (nh_).
#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_interface.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::ros_layer {

namespace {

void logOutcome(const std::string& service, const device::ServoStatus& status) {
  if (status.ok()) {
    ROS_DEBUG("%s: %s", service.c_str(), status.message.c_str());
  } else {
    ROS_DEBUG("%s failed (%s): %s", service.c_str(), device::toString(status.error),
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
    std::function<device::ServoStatus(typename Service::Request&, typename Service::Response&)>;

/// A request the service refused for what it asks (not for what the bus or the servo did).
bool refusedRequest(device::ServoError error) {
  using device::ServoError;
  return error == ServoError::kInvalidArgument || error == ServoError::kUnknownParam ||
         error == ServoError::kReadOnly || error == ServoError::kOutOfRange ||
         error == ServoError::kDangerous;
}

/// The node handle the servo/* services are advertised on, and where their refusals are counted.
struct ServoServiceSite {
  ros::NodeHandle& nh;
  device::InputRefusals& refusals;
};

/// Advertises one servo/* service from its call. The service logs the outcome, never throws
/// through to its caller (guardedService) and always returns true, so the caller gets the message
/// instead of a bare "service call failed".
template <typename Service>
ros::ServiceServer advertiseServo(ServoServiceSite site, const std::string& name,
                                  ServoCall<Service> call, Announce announce = Announce::kDebug) {
  using Request = typename Service::Request;
  using Response = typename Service::Response;
  device::InputRefusals& refusals = site.refusals;
  const boost::function<bool(Request&, Response&)> serve = [name, call, announce, &refusals](
                                                               Request& req, Response& res) {
    const device::ServoStatus status = call(req, res);
    logOutcome(name, status);
    if (refusedRequest(status.error)) refusals.refused(name);
    if (status.ok() && announce == Announce::kInfo) {
      ROS_INFO("%s: %s", name.c_str(), status.message.c_str());
    }
    setOutcome(res, status.ok(), servoStatusMessage(status));
    return true;
  };
  return site.nh.advertiseService<Request, Response>(
      name, guardedService<Request, Response>(refusals, name, serve));
}

}  // namespace

void ServoBusInterface::advertiseServices() {
  const ServoServiceSite site{nh_, inputRefusals()};
  const ServoServiceSite stop_site{stop_nh_, inputRefusals()};
  services_ = {
      advertiseServo<ServoPing>(
          site, "servo/ping",
          [this](ServoPing::Request& req, ServoPing::Response&) { return client_.ping(req.id); }),
      advertiseServo<ServoRead>(site, "servo/read",
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
          site, "servo/write",
          [this](ServoWrite::Request& req, ServoWrite::Response&) {
            return bus_.writeParam(req.id, req.param, req.value);
          },
          Announce::kInfo),
      advertiseServo<ServoReadAngle>(
          site, "servo/read_angle",
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
      advertiseServo<ServoMove>(site, "servo/move",
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
                                  const device::ServoStatus claimed =
                                      claimServos({req.id}, "servo/move");
                                  if (!claimed.ok()) return claimed;
                                  return bus_.move(request);
                                }),
      advertiseServo<ServoScan>(site, "servo/scan",
                                [this](ServoScan::Request& req, ServoScan::Response& res) {
                                  return client_.scan(req.first_id, req.last_id, &res.ids);
                                }),
      advertiseServo<ServoRotate>(site, "servo/rotate",
                                  [this](ServoRotate::Request& req, ServoRotate::Response&) {
                                    device::RotateRequest request;
                                    request.id = req.id;
                                    request.angle_deg = req.angle_deg;
                                    request.interval_ms = req.interval_ms;
                                    request.power_mw = req.power_mw;
                                    request.wait = req.wait;
                                    const device::ServoStatus claimed =
                                        claimServos({req.id}, "servo/rotate");
                                    if (!claimed.ok()) return claimed;
                                    return bus_.rotate(request);
                                  }),
      advertiseServo<ServoSpin>(stop_site, "servo/spin",
                                [this](ServoSpin::Request& req, ServoSpin::Response&) {
                                  device::SpinRequest request;
                                  request.id = req.id;
                                  request.clockwise = req.clockwise;
                                  request.mode = req.mode;
                                  request.speed_dps = req.speed_dps;
                                  request.value = req.value;
                                  request.wait = req.wait;
                                  // Served with the stops: it must never wait behind a long call.
                                  request.priority = device::BusPriority::kStop;
                                  // A SPIN stop is no motion: it works while the e-stop holds.
                                  if (req.mode != 0) {
                                    device::ServoStatus refused = refuseWhileEStopped("servo/spin");
                                    if (!refused.ok()) return refused;
                                  }
                                  yieldJoint(req.id, "servo/spin");
                                  return bus_.spin(request);
                                }),
      // Torque off moves nothing actively: allowed while the e-stop holds (motion_safety.h).
      advertiseServo<ServoDamping>(stop_site, "servo/damping",
                                   [this](ServoDamping::Request& req, ServoDamping::Response&) {
                                     yieldJoint(req.id, "servo/damping");
                                     return bus_.damping(req.id, req.power_mw, req.wait);
                                   }),
      advertiseServo<ServoRelax>(stop_site, "servo/relax",
                                 [this](ServoRelax::Request& req, ServoRelax::Response&) {
                                   yieldJoints(req.ids, "servo/relax");
                                   return bus_.relax(req.ids);
                                 }),
      advertiseServo<ServoHold>(stop_site, "servo/hold",
                                [this](ServoHold::Request& req, ServoHold::Response&) {
                                  const device::ServoStatus claimed =
                                      claimServos(req.ids, "servo/hold");
                                  if (!claimed.ok()) return claimed;
                                  return bus_.hold(req.ids);
                                }),
      advertiseServo<ServoReadAll>(site, "servo/read_all",
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
      // Reads only: allowed while the e-stop holds.
      advertiseServo<ServoInfo>(site, "servo/info",
                                [this](ServoInfo::Request& req, ServoInfo::Response& res) {
                                  device::ServoIdentity identity;
                                  const device::ServoStatus status = device::readServoInfo(
                                      client_, req.id, bus_.config().identity, &identity);
                                  res.servo_type = identity.servo_type;
                                  res.firmware_version = identity.firmware_version;
                                  res.serial_number = identity.serial_number;
                                  res.response_switch = identity.response_switch;
                                  return status;
                                }),
      advertiseServo<ServoResetUserData>(
          site, "servo/reset_user_data",
          [this](ServoResetUserData::Request& req, ServoResetUserData::Response&) {
            return bus_.resetUserData(req.id);
          },
          Announce::kInfo),
  };
}

}  // namespace serial_robot_driver::ros_layer
