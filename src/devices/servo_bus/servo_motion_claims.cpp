#include "serial_robot_driver/devices/servo_bus/servo_motion_claims.h"

#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"

namespace serial_robot_driver::device {

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

void ServoMotionClaims::yieldJoints(const std::vector<uint8_t>& ids, const char* source) {
  for (uint8_t id : ids.empty() ? bus_.config().polled_ids : ids) yieldJoint(id, source);
}

void ServoMotionClaims::yieldJoint(uint8_t id, const char* source) {
  const trajectory::BusJoint* joint = trajectory::findBusJoint(joints_, id);
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
    if (const trajectory::BusJoint* joint = trajectory::findBusJoint(joints_, move.id)) {
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
  trajectories_->setStateTimeout(names, trajectory::busStateTimeout(poll_rate));
}

}  // namespace serial_robot_driver::device
