#include "serial_robot_driver/devices/base/ros/base_conversions.h"

#include <algorithm>
#include <limits>

namespace serial_robot_driver::devices::base::ros {

sensor_msgs::BatteryState toBatteryState(const BatteryReading& battery, const ::ros::Time& stamp) {
  sensor_msgs::BatteryState msg;
  msg.header.stamp = stamp;
  // The base reports only a percentage; everything else is unknown (NaN per the message docs).
  const float unknown = std::numeric_limits<float>::quiet_NaN();
  msg.voltage = msg.temperature = msg.current = unknown;
  msg.charge = msg.capacity = msg.design_capacity = unknown;
  msg.percentage = static_cast<float>(battery.fraction);
  msg.power_supply_status = sensor_msgs::BatteryState::POWER_SUPPLY_STATUS_UNKNOWN;
  msg.power_supply_health = sensor_msgs::BatteryState::POWER_SUPPLY_HEALTH_UNKNOWN;
  msg.power_supply_technology = sensor_msgs::BatteryState::POWER_SUPPLY_TECHNOLOGY_UNKNOWN;
  msg.present = true;
  return msg;
}

nav_msgs::Odometry toOdometry(const OdometrySample& sample, const OdomFrames& frames,
                              const ::ros::Time& stamp) {
  nav_msgs::Odometry odom;
  fillOdometry(sample, frames, stamp, &odom);
  return odom;
}

void fillOdometry(const OdometrySample& sample, const OdomFrames& frames, const ::ros::Time& stamp,
                  nav_msgs::Odometry* msg) {
  const YawRotation rotation = yawRotation(sample.pose.yaw);
  msg->header.stamp = stamp;
  msg->header.frame_id = frames.odom;
  msg->child_frame_id = frames.base;
  // Planar: z, roll and pitch are zero; every field is set, whatever the last tick left.
  msg->pose.pose.position.x = sample.pose.x;
  msg->pose.pose.position.y = sample.pose.y;
  msg->pose.pose.position.z = 0.0;
  msg->pose.pose.orientation.x = 0.0;
  msg->pose.pose.orientation.y = 0.0;
  msg->pose.pose.orientation.z = rotation.z;
  msg->pose.pose.orientation.w = rotation.w;
  msg->twist.twist.linear.x = sample.linear;
  msg->twist.twist.linear.y = 0.0;
  msg->twist.twist.linear.z = 0.0;
  msg->twist.twist.angular.x = 0.0;
  msg->twist.twist.angular.y = 0.0;
  msg->twist.twist.angular.z = sample.angular;
  const OdometryCovariances covariances =
      odometryCovariances(sample.position_variance, sample.yaw_variance);
  std::copy(covariances.pose.begin(), covariances.pose.end(), msg->pose.covariance.begin());
  std::copy(covariances.twist.begin(), covariances.twist.end(), msg->twist.covariance.begin());
}

sensor_msgs::JointState toWheelStates(const OdometrySample& sample, const std::string& frame,
                                      const std::string& left, const std::string& right,
                                      const ::ros::Time& stamp) {
  sensor_msgs::JointState wheels;
  fillWheelStates(sample, frame, left, right, stamp, &wheels);
  return wheels;
}

void fillWheelStates(const OdometrySample& sample, const std::string& frame,
                     const std::string& left, const std::string& right, const ::ros::Time& stamp,
                     sensor_msgs::JointState* msg) {
  msg->header.stamp = stamp;
  msg->header.frame_id = frame;
  msg->name.resize(2);  // assigned element by element: each string keeps its buffer
  msg->name[0] = left;
  msg->name[1] = right;
  // In rad, from the controller: with the diameter each stretch of travel ran under.
  msg->position.assign({sample.wheel_angles.x(), sample.wheel_angles.y()});
  msg->velocity.assign({sample.wheel_rates.x(), sample.wheel_rates.y()});
  msg->effort.clear();
}

}  // namespace serial_robot_driver::devices::base::ros
