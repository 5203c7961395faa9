#include "serial_robot_driver/ros/trajectory_bus_joints.h"

#include <cmath>
#include <string>

namespace serial_robot_driver::ros_layer {

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
