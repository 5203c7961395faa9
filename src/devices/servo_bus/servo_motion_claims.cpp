#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"

#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"

namespace serial_robot_driver::devices::servo_bus {

ServoStatus ServoMotionClaims::refuseWhileEStopped(const std::string& source) {
  if (!e_stop_ || !e_stop_->refuse(source)) return {};
  return {ServoError::kMotionRefused,
          "e_stop is engaged: no servo moves until it is released (publish false on e_stop)"};
}

ServoStatus ServoMotionClaims::claimServos(const std::vector<uint8_t>& ids, const char* source) {
  ServoStatus refused = refuseWhileEStopped(source);
  if (refused.ok()) yieldJoints(ids, source);
  return refused;
}

ServoStatus ServoMotionClaims::move(const MoveRequest& request, const char* source) {
  const ServoStatus claimed = claimServos({request.id}, source);
  return claimed.ok() ? bus_.move(request) : claimed;
}

ServoStatus ServoMotionClaims::rotate(const RotateRequest& request, const char* source) {
  const ServoStatus claimed = claimServos({request.id}, source);
  return claimed.ok() ? bus_.rotate(request) : claimed;
}

ServoStatus ServoMotionClaims::hold(const std::vector<uint8_t>& ids, const char* source) {
  const ServoStatus claimed = claimServos(ids, source);
  return claimed.ok() ? bus_.hold(ids) : claimed;
}

ServoStatus ServoMotionClaims::spin(SpinRequest request, const char* source) {
  if (request.mode != 0) {
    ServoStatus refused = refuseWhileEStopped(source);
    if (!refused.ok()) return refused;
  }
  yieldJoint(request.id, source);
  // Served with the stops: it must never wait behind a long call.
  request.priority = BusPriority::kStop;
  return bus_.spin(request);
}

ServoStatus ServoMotionClaims::damping(uint8_t id, uint16_t power_mw, bool wait,
                                       const char* source) {
  yieldJoint(id, source);
  return bus_.damping(id, power_mw, wait);
}

ServoStatus ServoMotionClaims::relax(const std::vector<uint8_t>& ids, const char* source) {
  yieldJoints(ids, source);
  return bus_.relax(ids);
}

void ServoMotionClaims::yieldJoints(const std::vector<uint8_t>& ids, const char* source) {
  for (uint8_t id : ids.empty() ? bus_.config().polled_ids : ids) yieldJoint(id, source);
}

void ServoMotionClaims::yieldJoint(uint8_t id, const char* source) {
  const trajectory::BusJoint* joint = findBusJoint(joints_, id);
  if (!trajectories_ || !joint) return;
  trajectories_->takeOver({joint->name}, source, [&] {
    // A trajectory move still queued must not follow the service's command.
    bus_.dropQueuedMoves(id);
    return true;
  });
}

void ServoMotionClaims::queueCommand(const std::vector<MoveRequest>& moves, const char* source) {
  std::vector<std::string> joints;
  for (const MoveRequest& move : moves) {
    if (const trajectory::BusJoint* joint = findBusJoint(joints_, move.id)) {
      joints.push_back(joint->name);
    }
  }
  const auto queue = [&] {
    bus_.queueMoves(moves);
    return true;
  };
  if (trajectories_ && !joints.empty()) {
    trajectories_->takeOver(joints, source, queue);
  } else {
    queue();
  }
}

void ServoMotionClaims::followPollRate(double poll_rate) {
  if (!trajectories_ || joints_.empty()) return;
  std::vector<std::string> names;
  for (const trajectory::BusJoint& joint : joints_) names.push_back(joint.name);
  trajectories_->setStateTimeout(names, busStateTimeout(poll_rate));
}

}  // namespace serial_robot_driver::devices::servo_bus
