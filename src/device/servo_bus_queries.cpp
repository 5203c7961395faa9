// ServoBusClient's queries: PING, scan, READ_ANGLE and the multi-turn angle.
#include <cstdio>
#include <string>
#include <vector>

#include "serial_robot_driver/device/servo_bus_client.h"
#include "servo_bus_text.h"

namespace serial_robot_driver::device {

namespace servo = protocol::servo;
using servo::Command;
using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

ServoStatus ServoBusClient::pingLocked(uint8_t id) {
  servo::Packet answer;
  const ServoStatus status =
      exchangeLocked(servo::encodePing(id), Expectation(Command::kPing, id), &answer);
  if (!status.ok()) return status;
  return ok(servoName(id) + " is online (" + status.message + ")");
}

ServoStatus ServoBusClient::ping(uint8_t id) {
  if (auto rejection = rejectBroadcast(id, Command::kPing)) return *rejection;
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return pingLocked(id);
}

ServoStatus ServoBusClient::readAngle(uint8_t id, double* angle_deg, Clock::time_point* arrival,
                                      BusPriority priority) {
  if (auto rejection = rejectBroadcast(id, Command::kReadAngle)) return *rejection;
  servo::Packet answer;
  Clock::time_point answered_at;
  ServoStatus status;
  const std::vector<uint8_t> request = servo::encodeReadAngle(id);
  const Expectation expect(Command::kReadAngle, id);
  if (!takeBus(priority)) {
    return fail(ServoError::kPreempted, servoName(id) + "'s READ_ANGLE gave way to a stop");
  }
  {
    std::lock_guard<BusMutex> bus(bus_mutex_, std::adopt_lock);
    // Background work makes one attempt: the next poll is the retry.
    const ServoBusOptions options = this->options();
    const int attempts = priority == BusPriority::kBackground ? 1 : options.retries + 1;
    status = transact(request, expect, options.timeout, attempts, &answer, FrameGate::kSafetyAction,
                      priority == BusPriority::kWorker);
    std::lock_guard<std::mutex> lock(state_mutex_);
    answered_at = pending_.arrival;
  }
  if (!status.ok()) return status;
  const protocol::Decoded<servo::AngleAnswer> decoded = servo::decodeAngleAnswer(answer);
  if (!decoded) return fail(ServoError::kBadAnswer, servoName(id) + " sent an unreadable angle");
  if (arrival != nullptr) *arrival = answered_at;
  *angle_deg = decoded->angle_decidegrees / kDecidegreesPerDegree;
  // The poll reads no message: it would cost a formatted string on every transaction.
  if (priority == BusPriority::kBackground) return ok({});
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f deg", *angle_deg);
  return ok(servoName(id) + " is at " + text);
}

ServoStatus ServoBusClient::readMultiTurnAngle(uint8_t id, MultiTurnReading* reading) {
  if (auto rejection = rejectBroadcast(id, Command::kReadMultiTurnAngle)) return *rejection;
  servo::Packet answer;
  const ServoStatus status = exchange(servo::encodeReadMultiTurnAngle(id),
                                      Expectation(Command::kReadMultiTurnAngle, id), &answer);
  if (!status.ok()) return status;
  const protocol::Decoded<servo::MultiTurnAngle> decoded = servo::decodeMultiTurnAngle(answer);
  if (!decoded) {
    return fail(ServoError::kBadAnswer, servoName(id) + " sent an unreadable multi-turn angle");
  }
  reading->angle_deg = decoded->angle_decidegrees / kDecidegreesPerDegree;
  reading->turns = decoded->turns;
  char text[64];
  std::snprintf(text, sizeof(text), "%.1f deg (%d turns)", reading->angle_deg, reading->turns);
  return ok(servoName(id) + " is at " + text);
}

ServoStatus ServoBusClient::pingOnceLocked(uint8_t id) {
  servo::Packet answer;
  return transact(servo::encodePing(id), Expectation(Command::kPing, id), options().timeout, 1,
                  &answer);
}

ServoStatus ServoBusClient::scan(uint8_t first_id, uint8_t last_id, std::vector<uint8_t>* ids) {
  if (first_id > last_id) {
    return fail(ServoError::kInvalidArgument, "first_id " + std::to_string(first_id) +
                                                  " is above last_id " + std::to_string(last_id));
  }
  if (last_id == servo::kBroadcastId) {
    return fail(ServoError::kInvalidArgument,
                "id 255 is the broadcast address and cannot be scanned (ids 0..254)");
  }
  ids->clear();
  for (int id = first_id; id <= last_id; ++id) {
    // The bus is taken per id: a service call or a poll waits for one PING at most.
    std::lock_guard<BusMutex> bus(bus_mutex_);
    const ServoStatus status = pingOnceLocked(static_cast<uint8_t>(id));
    if (status.ok()) {
      ids->push_back(static_cast<uint8_t>(id));
    } else if (status.error != ServoError::kTimeout && status.error != ServoError::kBadAnswer) {
      return fail(status.error, "scan stopped at id " + std::to_string(id) + ": " + status.message);
    }
  }
  std::string list;
  for (uint8_t id : *ids) list += (list.empty() ? "" : ", ") + std::to_string(id);
  return ok(std::to_string(ids->size()) + " of " + std::to_string(last_id - first_id + 1) +
            " ids answered PING" + (list.empty() ? "" : ": " + list));
}

}  // namespace serial_robot_driver::device
