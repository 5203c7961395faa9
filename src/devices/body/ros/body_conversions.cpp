#include "serial_robot_driver/devices/body/ros/body_conversions.h"

#include <algorithm>

namespace serial_robot_driver::devices::body::ros {

namespace {
geometry_msgs::Vector3 toVector3(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 msg;
  msg.x = v.x();
  msg.y = v.y();
  msg.z = v.z();
  return msg;
}

geometry_msgs::Quaternion toQuaternion(const Quaternion& q) {
  geometry_msgs::Quaternion msg;
  msg.x = q.x;
  msg.y = q.y;
  msg.z = q.z;
  msg.w = q.w;
  return msg;
}
}  // namespace

sensor_msgs::JointState toJointState(const Telemetry& telemetry,
                                     const std::vector<BodyJoint>& joints,
                                     const ::ros::Time& stamp) {
  return toJointState(jointReadings(telemetry, joints), stamp);
}

sensor_msgs::JointState toJointState(const JointReadings& readings, const ::ros::Time& stamp) {
  sensor_msgs::JointState msg;
  fillJointState(readings, stamp, &msg);
  return msg;
}

void fillJointState(const JointReadings& readings, const ::ros::Time& stamp,
                    sensor_msgs::JointState* msg) {
  msg->name = readings.names;
  fillJointStateValues(readings, stamp, msg);
}

void fillJointStateValues(const JointReadings& readings, const ::ros::Time& stamp,
                          sensor_msgs::JointState* msg) {
  msg->header.stamp = stamp;
  msg->header.frame_id.clear();
  msg->position = readings.positions;
  msg->velocity = readings.velocities;
  msg->effort.clear();
}

JointCommand fromJointState(const sensor_msgs::JointState& msg) {
  return JointCommand{msg.name, msg.position};
}

sensor_msgs::Imu toImu(const Telemetry& telemetry, const ImuParams& params,
                       const ::ros::Time& stamp, const std::array<double, 3>& gyro_bias) {
  sensor_msgs::Imu msg;
  fillImu(imuReading(telemetry, params, gyro_bias), params, stamp, &msg);
  return msg;
}

void fillImu(const ImuReading& reading, const ImuParams& params, const ::ros::Time& stamp,
             sensor_msgs::Imu* msg) {
  msg->header.stamp = stamp;
  msg->header.frame_id = params.frame_id;
  msg->linear_acceleration = toVector3(reading.linear_acceleration);
  msg->angular_velocity = toVector3(reading.angular_velocity);
  msg->orientation = toQuaternion(reading.orientation);
  const ImuCovariances covariances = imuCovariances(params);
  std::copy(covariances.orientation.begin(), covariances.orientation.end(),
            msg->orientation_covariance.begin());
  std::copy(covariances.angular_velocity.begin(), covariances.angular_velocity.end(),
            msg->angular_velocity_covariance.begin());
  std::copy(covariances.linear_acceleration.begin(), covariances.linear_acceleration.end(),
            msg->linear_acceleration_covariance.begin());
}

std::optional<serial_robot_driver::FootPressure> toFootPressure(const Telemetry& telemetry,
                                                                const ::ros::Time& stamp,
                                                                const std::string& frame_id) {
  if (!telemetry.has_foot) return std::nullopt;
  serial_robot_driver::FootPressure msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  for (std::size_t j = 0; j < kFootSensorCount; ++j) msg.pressure[j] = telemetry.foot[j];
  return msg;
}

serial_robot_driver::Telemetry toTelemetryMsg(const Telemetry& telemetry,
                                              const std::vector<BodyJoint>& joints,
                                              const ::ros::Time& stamp) {
  serial_robot_driver::Telemetry msg;
  msg.header.stamp = stamp;
  const std::size_t count = telemetry.servo_count;
  msg.servo_ids.resize(count);
  msg.positions.resize(count);
  msg.speeds.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    // Ids come from the configuration: the frame itself does not carry them.
    msg.servo_ids[i] = i < joints.size() ? joints[i].servo_id : 0;
    msg.positions[i] = telemetry.servos[i].position;
    msg.speeds[i] = telemetry.servos[i].speed;
  }
  for (std::size_t k = 0; k < kImuValueCount; ++k) msg.imu[k] = telemetry.imu[k];
  msg.has_foot = telemetry.has_foot;
  if (telemetry.has_foot) msg.foot.assign(telemetry.foot.begin(), telemetry.foot.end());
  return msg;
}

}  // namespace serial_robot_driver::devices::body::ros
