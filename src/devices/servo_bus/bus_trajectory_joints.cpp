#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::devices::servo_bus {

namespace {
constexpr double kMaxRotateIntervalMs = 65535.0;  // ROTATE's interval is a u16
}  // namespace

std::vector<BusJoint> makeBusJoints(const devices::servo_bus::ServoBusParams& params) {
  std::vector<BusJoint> joints;
  for (std::size_t i = 0; i < params.joint_ids.size(); ++i) {
    BusJoint joint;
    joint.id = static_cast<uint8_t>(params.joint_ids[i]);
    joint.name = params.joint_names.at(i);
    joint.zero_deg = params.joint_zero_deg.empty() ? 0.0 : params.joint_zero_deg.at(i);
    joint.direction = params.joint_directions.empty() ? 1 : params.joint_directions.at(i);
    joints.push_back(joint);
  }
  return joints;
}

const BusJoint* findBusJoint(const std::vector<BusJoint>& joints, uint8_t id) {
  const auto it = std::find_if(joints.begin(), joints.end(),
                               [id](const BusJoint& joint) { return joint.id == id; });
  return it == joints.end() ? nullptr : &*it;
}

JointPosition busJointPosition(const std::vector<BusJoint>& joints, uint8_t id, double angle_deg) {
  if (const BusJoint* joint = findBusJoint(joints, id)) {
    return {joint->name, joint->toRadians(angle_deg)};
  }
  return {"servo_" + std::to_string(id), angle_deg * M_PI / 180.0};
}

double busStateTimeout(double state_rate) { return std::max(0.5, 3.0 / state_rate); }

TrajectoryJoints busTrajectoryJoints(const std::vector<BusJoint>& joints, QueueServoMove queue_move,
                                     double state_rate, StopServo stop_servo) {
  TrajectoryJoints result;
  for (const BusJoint& joint : joints) result.joints.push_back(joint.range());
  result.state_timeout = busStateTimeout(state_rate);
  if (stop_servo) {
    result.stop = [joints, stop_servo](std::size_t index) {
      return stop_servo(joints.at(index).id);
    };
  }
  result.move = [joints, queue_move](std::size_t index, double position, double duration) {
    const BusJoint& joint = joints.at(index);
    // A segment longer than ROTATE can say is given its longest interval; the next segment's
    // move, or the goal tolerance, catches up.
    const double interval_ms = std::clamp(std::round(duration * 1000.0), 0.0, kMaxRotateIntervalMs);
    return queue_move(joint.id, joint.toServoDegrees(position), static_cast<uint32_t>(interval_ms));
  };
  return result;
}

}  // namespace serial_robot_driver::devices::servo_bus
