#include "serial_robot_driver/devices/body/body_readings.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

namespace serial_robot_driver::devices::body {

std::vector<BodyJoint> makeBodyJoints(const BodyParams& params) {
  std::vector<BodyJoint> joints(params.servo_ids.size());
  for (std::size_t i = 0; i < joints.size(); ++i) {
    BodyJoint& joint = joints[i];
    joint.servo_id = static_cast<uint8_t>(params.servo_ids[i]);
    joint.name = i < params.joint_names.size() ? params.joint_names[i] : "";
    joint.calibration = params.calibration;  // what every joint shares, then its own
    if (i < params.zero_ticks.size()) joint.calibration.zero_ticks = params.zero_ticks[i];
    if (i < params.directions.size()) joint.calibration.direction = params.directions[i];
  }
  return joints;
}

JointReadings jointReadings(const Telemetry& telemetry, const std::vector<BodyJoint>& joints) {
  JointReadings readings;
  updateJointReadings(telemetry, joints, &readings);
  return readings;
}

void updateJointReadings(const Telemetry& telemetry, const std::vector<BodyJoint>& joints,
                         JointReadings* readings) {
  updateJointReadings(telemetry, makeJointConversion(joints), readings);
}

JointConversion makeJointConversion(const std::vector<BodyJoint>& joints) {
  JointConversion conversion;
  conversion.names.reserve(joints.size());
  conversion.calibrations.reserve(joints.size());
  for (const BodyJoint& joint : joints) {
    conversion.names.push_back(joint.name);
    conversion.calibrations.push_back(joint.calibration);
  }
  return conversion;
}

void updateJointReadings(const Telemetry& telemetry, const JointConversion& joints,
                         JointReadings* readings) {
  const std::size_t count = std::min(joints.calibrations.size(), telemetry.servo_count);
  if (readings->names.size() != count) {
    readings->names.assign(joints.names.begin(), joints.names.begin() + count);
    ++readings->names_generation;
  }
  // The speed's unit is not documented: without a known scale the velocity stays empty rather
  // than guessed.
  const bool velocity_known = count > 0 && joints.calibrations.front().velocity_scale > 0;
  readings->positions.resize(count);
  readings->velocities.resize(velocity_known ? count : 0);
  for (std::size_t i = 0; i < count; ++i) {
    const JointCalibration& calibration = joints.calibrations[i];
    readings->positions[i] = calibration.toRadians(telemetry.servos[i].position);
    if (velocity_known) {
      readings->velocities[i] = calibration.toRadiansPerSecond(telemetry.servos[i].speed);
    }
  }
}

Quaternion quaternionFromRollPitchYaw(double roll, double pitch, double yaw) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return {q.x(), q.y(), q.z(), q.w()};
}

Eigen::Matrix3d axisMapMatrix(const std::vector<std::string>& axis_map) {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
  const std::optional<AxisMap> map = parseAxisMap(axis_map, nullptr);
  if (!map) return Eigen::Matrix3d::Identity();  // validate() refuses such a map at start-up
  for (int i = 0; i < 3; ++i) matrix(i, map->source[i]) = map->sign[i];
  return matrix;
}

namespace {
/// R_world_imu from the board's attitude angles and the axis map M (v_imu = M v_sensor).
Eigen::Quaterniond imuOrientation(const Telemetry& telemetry, double angle_scale,
                                  const Eigen::Matrix3d& map) {
  const auto& raw = telemetry.imu;
  const Quaternion sensor = quaternionFromRollPitchYaw(
      raw[kRoll] * angle_scale, raw[kPitch] * angle_scale, raw[kYaw] * angle_scale);
  return Eigen::Quaterniond(sensor.w, sensor.x, sensor.y, sensor.z) *
         Eigen::Quaterniond(map.transpose());
}
}  // namespace

double imuYaw(const Telemetry& telemetry, const ImuParams& params) {
  return imuYaw(telemetry, params, axisMapMatrix(params.axis_map));
}

double imuYaw(const Telemetry& telemetry, const ImuParams& params, const Eigen::Matrix3d& axes) {
  const Eigen::Quaterniond q = imuOrientation(telemetry, params.angle_scale, axes);
  // The Z (yaw) angle of a Z-Y-X decomposition.
  return std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()),
                    1.0 - 2.0 * (q.y() * q.y() + q.z() * q.z()));
}

ImuReading imuReading(const Telemetry& telemetry, const ImuParams& params,
                      const std::array<double, 3>& gyro_bias) {
  return imuReading(telemetry, params, axisMapMatrix(params.axis_map), gyro_bias);
}

ImuReading imuReading(const Telemetry& telemetry, const ImuParams& params,
                      const Eigen::Matrix3d& map, const std::array<double, 3>& gyro_bias) {
  const auto& raw = telemetry.imu;
  // The axis map M turns sensor-frame vectors into imu-frame ones (v_imu = M v_sensor); the
  // sensor's orientation R_world_sensor becomes R_world_imu = R_world_sensor * M^T.
  ImuReading reading;
  reading.linear_acceleration =
      map * Eigen::Vector3d(raw[kAccelX], raw[kAccelY], raw[kAccelZ]) * params.accel_scale;
  reading.angular_velocity = map *
                             (Eigen::Vector3d(raw[kGyroX], raw[kGyroY], raw[kGyroZ]) -
                              Eigen::Vector3d(gyro_bias[0], gyro_bias[1], gyro_bias[2])) *
                             params.gyro_scale;
  const Eigen::Quaterniond world_imu = imuOrientation(telemetry, params.angle_scale, map);
  reading.orientation = {world_imu.x(), world_imu.y(), world_imu.z(), world_imu.w()};
  return reading;
}

ImuCovariances imuCovariances(const ImuParams& params) {
  ImuCovariances covariances;
  for (std::size_t i = 0; i < 3; ++i) {  // the diagonal: elements 0, 4, 8
    covariances.orientation[4 * i] = params.orientation_variance;
    covariances.angular_velocity[4 * i] = params.angular_velocity_variance;
    covariances.linear_acceleration[4 * i] = params.linear_acceleration_variance;
  }
  if (params.orientation_variance < 0) {
    covariances.orientation = {};
    covariances.orientation[0] = -1.0;
  }
  return covariances;
}

}  // namespace serial_robot_driver::devices::body
