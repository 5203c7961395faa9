#include "serial_robot_driver/ros/trajectory_bus_joints.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::ros_layer {

namespace {
constexpr double kMaxRotateIntervalMs = 65535.0;  // ROTATE's interval is a u16
}  // namespace

std::vector<trajectory::BusJoint> makeBusJoints(const ServoBusParams& params) {
  std::vector<trajectory::BusJoint> joints;
  for (std::size_t i = 0; i < params.joint_ids.size(); ++i) {
    trajectory::BusJoint joint;
    joint.id = static_cast<uint8_t>(params.joint_ids[i]);
    joint.name = params.joint_names.at(i);
    joint.zero_deg = params.joint_zero_deg.empty() ? 0.0 : params.joint_zero_deg.at(i);
    joint.direction = params.joint_directions.empty() ? 1 : params.joint_directions.at(i);
    joints.push_back(joint);
  }
  return joints;
}

const trajectory::BusJoint* findBusJoint(const std::vector<trajectory::BusJoint>& joints,
                                         uint8_t id) {
  const auto it = std::find_if(joints.begin(), joints.end(),
                               [id](const trajectory::BusJoint& joint) { return joint.id == id; });
  return it == joints.end() ? nullptr : &*it;
}

double busStateTimeout(double state_rate) { return std::max(0.5, 3.0 / state_rate); }

TrajectoryJoints busTrajectoryJoints(const std::vector<trajectory::BusJoint>& joints,
                                     QueueServoMove queue_move, double state_rate,
                                     StopServo stop_servo) {
  TrajectoryJoints result;
  for (const trajectory::BusJoint& joint : joints) result.joints.push_back(joint.range());
  result.state_timeout = busStateTimeout(state_rate);
  if (stop_servo) {
    result.stop = [joints, stop_servo](std::size_t index) {
      return stop_servo(joints.at(index).id);
    };
  }
  result.move = [joints, queue_move](std::size_t index, double position, double duration) {
    const trajectory::BusJoint& joint = joints.at(index);
    // A segment longer than ROTATE can say is given its longest interval; the next segment's
    // move, or the goal tolerance, catches up.
    const double interval_ms = std::clamp(std::round(duration * 1000.0), 0.0, kMaxRotateIntervalMs);
    return queue_move(joint.id, joint.toServoDegrees(position), static_cast<uint32_t>(interval_ms));
  };
  return result;
}

sensor_msgs::JointState busJointState(const std::vector<trajectory::BusJoint>& joints, uint8_t id,
                                      double angle_deg, const ros::Time& stamp) {
  sensor_msgs::JointState msg;
  msg.header.stamp = stamp;
  if (const trajectory::BusJoint* joint = findBusJoint(joints, id)) {
    msg.name.push_back(joint->name);
    msg.position.push_back(joint->toRadians(angle_deg));
  } else {
    msg.name.push_back("servo_" + std::to_string(id));
    msg.position.push_back(angle_deg * M_PI / 180.0);
  }
  return msg;
}

}  // namespace serial_robot_driver::ros_layer
