#include "serial_robot_driver/devices/servo_bus/servo_services.h"

#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_device.h"  // servoStatusMessage

namespace serial_robot_driver::devices::servo_bus {

void ServoServices::conclude(const char* service, const ServoStatus& status, ServoReply& reply,
                             Announce announce) const {
  const std::string name(service);
  if (status.ok()) {
    core::log(core::LogLevel::kDebug, "%s: %s", service, status.message.c_str());
  } else {
    core::log(core::LogLevel::kDebug, "%s failed (%s): %s", service, toString(status.error),
              status.message.c_str());
  }
  if (refusesRequest(status.error)) refusals_.refused(name);
  if (status.ok() && announce == Announce::kInfo) {
    core::log(core::LogLevel::kInfo, "%s: %s", service, status.message.c_str());
  }
  reply.ok = status.ok();
  reply.message = servoStatusMessage(status);
}

ServoReply ServoServices::concluded(const char* service, const ServoStatus& status,
                                    Announce announce) const {
  ServoReply reply;
  conclude(service, status, reply, announce);
  return reply;
}

ServoReply ServoServices::ping(uint8_t id) {
  return concluded(servo_service::kPing, bus_.client().ping(id));
}

ServoReadReply ServoServices::read(uint8_t id, const std::string& param) {
  ServoParamValue value;
  const ServoStatus status = bus_.client().readParam(id, param, &value);
  ServoReadReply reply;
  if (status.ok()) {
    reply.value = value.value;
    reply.unit = value.unit;
  }
  conclude(servo_service::kRead, status, reply);
  return reply;
}

ServoAngleReply ServoServices::readAngle(uint8_t id, bool multi_turn) {
  ServoAngleReply reply;
  ServoStatus status;
  if (multi_turn) {
    MultiTurnReading reading;
    status = bus_.client().readMultiTurnAngle(id, &reading);
    if (status.ok()) {
      reply.angle_deg = reading.angle_deg;
      reply.turns = reading.turns;
    }
  } else {
    double angle_deg = 0.0;
    status = bus_.client().readAngle(id, &angle_deg);
    if (status.ok()) reply.angle_deg = angle_deg;
  }
  conclude(servo_service::kReadAngle, status, reply);
  return reply;
}

ServoScanReply ServoServices::scan(uint8_t first_id, uint8_t last_id) {
  ServoScanReply reply;
  conclude(servo_service::kScan, bus_.client().scan(first_id, last_id, &reply.ids), reply);
  return reply;
}

ServoReadAllReply ServoServices::readAll(uint8_t id) {
  std::vector<ServoParamValue> values;
  const ServoStatus status = bus_.client().readAll(id, &values);
  ServoReadAllReply reply;
  for (const ServoParamValue& value : values) {
    reply.names.push_back(value.name);
    reply.values.push_back(value.value);
  }
  conclude(servo_service::kReadAll, status, reply);
  return reply;
}

ServoInfoReply ServoServices::info(uint8_t id) {
  ServoInfoReply reply;
  const ServoStatus status =
      readServoInfo(bus_.client(), id, bus_.config().identity, &reply.identity);
  conclude(servo_service::kInfo, status, reply);
  return reply;
}

ServoReply ServoServices::write(uint8_t id, const std::string& param, int64_t value) {
  return concluded(servo_service::kWrite, bus_.writeParam(id, param, value), Announce::kInfo);
}

ServoReply ServoServices::resetUserData(uint8_t id) {
  return concluded(servo_service::kResetUserData, bus_.resetUserData(id), Announce::kInfo);
}

ServoReply ServoServices::move(const MoveRequest& request) {
  return concluded(servo_service::kMove, claims_.move(request, servo_service::kMove));
}

ServoReply ServoServices::rotate(const RotateRequest& request) {
  return concluded(servo_service::kRotate, claims_.rotate(request, servo_service::kRotate));
}

ServoReply ServoServices::spin(const SpinRequest& request) {
  return concluded(servo_service::kSpin, claims_.spin(request, servo_service::kSpin));
}

ServoReply ServoServices::damping(uint8_t id, uint16_t power_mw, bool wait) {
  return concluded(servo_service::kDamping,
                   claims_.damping(id, power_mw, wait, servo_service::kDamping));
}

ServoReply ServoServices::relax(const std::vector<uint8_t>& ids) {
  return concluded(servo_service::kRelax, claims_.relax(ids, servo_service::kRelax));
}

ServoReply ServoServices::hold(const std::vector<uint8_t>& ids) {
  return concluded(servo_service::kHold, claims_.hold(ids, servo_service::kHold));
}

}  // namespace serial_robot_driver::devices::servo_bus
