#include "serial_robot_driver/ros/conversions.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace serial_robot_driver::ros_layer {

namespace body = protocol::body;

ros::Time toRosTime(std::chrono::steady_clock::time_point event, const ros::Time& ros_now,
                    std::chrono::steady_clock::time_point steady_now) {
  const auto age = std::chrono::duration_cast<std::chrono::nanoseconds>(steady_now - event);
  const ros::Duration age_ros(std::chrono::duration<double>(age).count());
  // An event "in the future" (clock read order) is now; one before the epoch is the epoch.
  if (age_ros <= ros::Duration(0)) return ros_now;
  if (ros_now.toSec() <= age_ros.toSec()) return ros::Time(0);
  return ros_now - age_ros;
}

ros::Time toRosTime(std::chrono::steady_clock::time_point event) {
  // Read both clocks back to back so the offset between them is as exact as it can be.
  const auto steady_now = std::chrono::steady_clock::now();
  const ros::Time ros_now = ros::Time::now();
  return toRosTime(event, ros_now, steady_now);
}

ros::Time ArrivalStamps::operator()(std::chrono::steady_clock::time_point arrival) const {
  if (replay_timeline_) {
    const int64_t recorded_ns = replay_timeline_->recordedAt(arrival).count();
    ros::Time stamp;
    stamp.fromNSec(static_cast<uint64_t>(std::max<int64_t>(recorded_ns, 0)));
    return stamp;
  }
  thread_local std::chrono::steady_clock::time_point last_arrival{};
  thread_local ros::Time last_stamp;
  if (arrival != last_arrival || last_stamp.isZero()) {
    last_stamp = toRosTime(arrival);
    last_arrival = arrival;
  }
  return last_stamp;
}

std::vector<device::BodyJoint> makeBodyJoints(const BodyParams& params) {
  std::vector<device::BodyJoint> joints(params.servo_ids.size());
  for (std::size_t i = 0; i < joints.size(); ++i) {
    device::BodyJoint& joint = joints[i];
    joint.servo_id = static_cast<uint8_t>(params.servo_ids[i]);
    joint.name = i < params.joint_names.size() ? params.joint_names[i] : "";
    joint.calibration = params.calibration;  // what every joint shares, then its own
    if (i < params.zero_ticks.size()) joint.calibration.zero_ticks = params.zero_ticks[i];
    if (i < params.directions.size()) joint.calibration.direction = params.directions[i];
  }
  return joints;
}

geometry_msgs::Quaternion quaternionFromRollPitchYaw(double roll, double pitch, double yaw) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  geometry_msgs::Quaternion msg;
  msg.x = q.x();
  msg.y = q.y();
  msg.z = q.z();
  msg.w = q.w();
  return msg;
}

Eigen::Matrix3d axisMapMatrix(const std::vector<std::string>& axis_map) {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
  const std::optional<AxisMap> map = parseAxisMap(axis_map, nullptr);
  if (!map) return Eigen::Matrix3d::Identity();  // validate() refuses such a map at start-up
  for (int i = 0; i < 3; ++i) matrix(i, map->source[i]) = map->sign[i];
  return matrix;
}

sensor_msgs::JointState toJointState(const body::Telemetry& telemetry,
                                     const std::vector<device::BodyJoint>& joints,
                                     const ros::Time& stamp) {
  sensor_msgs::JointState msg;
  msg.header.stamp = stamp;
  const std::size_t count = std::min(joints.size(), telemetry.servo_count);
  msg.name.reserve(count);
  msg.position.reserve(count);
  // The speed's unit is not documented: without a known scale the velocity stays empty rather
  // than guessed (JointState allows an empty velocity array).
  const bool velocity_known = count > 0 && joints.front().calibration.velocity_scale > 0;
  if (velocity_known) msg.velocity.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const device::JointCalibration& calibration = joints[i].calibration;
    msg.name.push_back(joints[i].name);
    msg.position.push_back(calibration.toRadians(telemetry.servos[i].position));
    if (velocity_known) {
      msg.velocity.push_back(calibration.toRadiansPerSecond(telemetry.servos[i].speed));
    }
  }
  return msg;
}

namespace {
/// R_world_imu from the board's attitude angles and the axis map M (v_imu = M v_sensor).
Eigen::Quaterniond imuOrientation(const body::Telemetry& telemetry, double angle_scale,
                                  const Eigen::Matrix3d& map) {
  const auto& raw = telemetry.imu;
  const geometry_msgs::Quaternion sensor =
      quaternionFromRollPitchYaw(raw[body::kRoll] * angle_scale, raw[body::kPitch] * angle_scale,
                                 raw[body::kYaw] * angle_scale);
  return Eigen::Quaterniond(sensor.w, sensor.x, sensor.y, sensor.z) *
         Eigen::Quaterniond(map.transpose());
}
}  // namespace

double imuYaw(const body::Telemetry& telemetry, const ImuParams& params) {
  const Eigen::Quaterniond q =
      imuOrientation(telemetry, params.angle_scale, axisMapMatrix(params.axis_map));
  // The Z (yaw) angle of a Z-Y-X decomposition.
  return std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()),
                    1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
}

sensor_msgs::Imu toImu(const body::Telemetry& telemetry, const ImuParams& params,
                       const ros::Time& stamp, const std::array<double, 3>& gyro_bias) {
  sensor_msgs::Imu msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = params.frame_id;
  const auto& raw = telemetry.imu;
  // The axis map M turns sensor-frame vectors into imu-frame ones (v_imu = M v_sensor); the
  // sensor's orientation R_world_sensor becomes R_world_imu = R_world_sensor * M^T.
  const Eigen::Matrix3d map = axisMapMatrix(params.axis_map);
  const Eigen::Vector3d accel =
      map * Eigen::Vector3d(raw[body::kAccelX], raw[body::kAccelY], raw[body::kAccelZ]) *
      params.accel_scale;
  const Eigen::Vector3d gyro =
      map *
      (Eigen::Vector3d(raw[body::kGyroX], raw[body::kGyroY], raw[body::kGyroZ]) -
       Eigen::Vector3d(gyro_bias[0], gyro_bias[1], gyro_bias[2])) *
      params.gyro_scale;
  msg.linear_acceleration.x = accel.x();
  msg.linear_acceleration.y = accel.y();
  msg.linear_acceleration.z = accel.z();
  msg.angular_velocity.x = gyro.x();
  msg.angular_velocity.y = gyro.y();
  msg.angular_velocity.z = gyro.z();
  const Eigen::Quaterniond world_imu = imuOrientation(telemetry, params.angle_scale, map);
  msg.orientation.x = world_imu.x();
  msg.orientation.y = world_imu.y();
  msg.orientation.z = world_imu.z();
  msg.orientation.w = world_imu.w();
  // Row-major 3x3 matrices: the diagonal is elements 0, 4, 8.
  for (std::size_t i = 0; i < 3; ++i) {
    msg.orientation_covariance[4 * i] = params.orientation_variance;
    msg.angular_velocity_covariance[4 * i] = params.angular_velocity_variance;
    msg.linear_acceleration_covariance[4 * i] = params.linear_acceleration_variance;
  }
  if (params.orientation_variance < 0) {
    // REP-145: element 0 = -1 says "no orientation estimate"; the rest is ignored.
    msg.orientation_covariance = {};
    msg.orientation_covariance[0] = -1.0;
  }
  return msg;
}

std::optional<serial_robot_driver::FootPressure> toFootPressure(const body::Telemetry& telemetry,
                                                                const ros::Time& stamp,
                                                                const std::string& frame_id) {
  if (!telemetry.has_foot) return std::nullopt;
  serial_robot_driver::FootPressure msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame_id;
  for (std::size_t j = 0; j < body::kFootSensorCount; ++j) msg.pressure[j] = telemetry.foot[j];
  return msg;
}

serial_robot_driver::Telemetry toTelemetryMsg(const body::Telemetry& telemetry,
                                              const std::vector<device::BodyJoint>& joints,
                                              const ros::Time& stamp) {
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
  for (std::size_t k = 0; k < body::kImuValueCount; ++k) msg.imu[k] = telemetry.imu[k];
  msg.has_foot = telemetry.has_foot;
  if (telemetry.has_foot) msg.foot.assign(telemetry.foot.begin(), telemetry.foot.end());
  return msg;
}

JointCommand fromJointState(const sensor_msgs::JointState& msg) {
  return JointCommand{msg.name, msg.position};
}

void writeStatusReport(const device::StatusReport& report,
                       diagnostic_updater::DiagnosticStatusWrapper& status, SummaryWrite summary) {
  static_assert(static_cast<unsigned char>(device::StatusLevel::kWarn) ==
                        diagnostic_msgs::DiagnosticStatus::WARN &&
                    static_cast<unsigned char>(device::StatusLevel::kError) ==
                        diagnostic_msgs::DiagnosticStatus::ERROR &&
                    static_cast<unsigned char>(device::StatusLevel::kStale) ==
                        diagnostic_msgs::DiagnosticStatus::STALE,
                "StatusLevel's values are DiagnosticStatus's levels");
  const auto level = static_cast<unsigned char>(report.level);
  if (summary == SummaryWrite::kReplace) {
    status.summary(level, report.message);
  } else {
    status.mergeSummary(level, report.message);
  }
  if (!report.hardware_id.empty()) status.hardware_id = report.hardware_id;
  for (const auto& [key, value] : report.values) status.add(key, value);
}

}  // namespace serial_robot_driver::ros_layer
