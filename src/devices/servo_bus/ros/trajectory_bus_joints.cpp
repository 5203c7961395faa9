#include "serial_robot_driver/devices/servo_bus/ros/trajectory_bus_joints.h"

namespace serial_robot_driver::devices::servo_bus::ros {

sensor_msgs::JointState busJointState(const JointPosition& measured, const ::ros::Time& stamp) {
  sensor_msgs::JointState msg;
  msg.header.stamp = stamp;
  msg.name.push_back(measured.name);
  msg.position.push_back(measured.position);
  return msg;
}

sensor_msgs::JointState busJointState(const std::vector<trajectory::BusJoint>& joints, uint8_t id,
                                      double angle_deg, const ::ros::Time& stamp) {
  return busJointState(busJointPosition(joints, id, angle_deg), stamp);
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
