// The body's parameter sections (~body/... and its IMU's ~imu/...): rows in
// src/devices/body/body_module.cpp.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/params/device_sections.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::devices::body {
struct GyroUnits;
}

namespace serial_robot_driver::devices::body {

struct BodyParams : params::DevicePortParams {
  std::vector<int> servo_ids{1, 2};
  std::vector<std::string> joint_names{"joint_1", "joint_2"};
  /// What every joint shares: ticks_per_revolution and velocity_scale (0: unknown, and
  /// joint_states carries no velocity) are bound here; each joint's zero and direction come from
  /// the lists below (makeBodyJoints).
  JointCalibration calibration;
  std::vector<int> zero_ticks{2048, 2048};
  std::vector<int> directions{1, 1};
};

/// Where each axis of imu/data comes from: axis i (x, y, z) is sign[i] * the sensor's axis
/// source[i]. Written as ~imu/axis_map, e.g. ["x", "y", "z"] (as mounted) or ["-y", "x", "z"].
struct AxisMap {
  std::array<int, 3> source{0, 1, 2};
  std::array<int, 3> sign{1, 1, 1};
};

/// Parses an axis map: three entries "x", "y" or "z" with an optional sign, each sensor axis once,
/// and right-handed (a rotation, so the orientation can follow). nullopt with `problem` set when
/// not.
std::optional<AxisMap> parseAxisMap(const std::vector<std::string>& entries, std::string* problem);

struct ImuParams {
  std::string frame_id = "imu_link";
  std::vector<std::string> axis_map{"x", "y", "z"};  ///< see AxisMap
  double accel_scale = 0.0047884;                    ///< m/s^2 per LSB (16 g / 32768)
  double gyro_scale = 0.0010653;                     ///< rad/s per LSB (2000 deg/s / 32768)
  double angle_scale = 0.0000958738;                 ///< rad per LSB (180 deg / 32768)
  /// Diagonal variances (REP-145); a negative orientation variance would mean "no orientation".
  double orientation_variance = 0.0003;        ///< rad^2 (about 1 deg std)
  double angular_velocity_variance = 0.0001;   ///< (rad/s)^2
  double linear_acceleration_variance = 0.01;  ///< (m/s^2)^2
  double calibration_time = 2.0;               ///< s of gyro averaged by imu/calibrate
  /// Calibrate the gyro bias once, when telemetry first arrives and the base is still.
  bool calibrate_on_start = false;
};

/// The keys of the body's sections (DeviceModule::sections): its own and its IMU's.
extern const params::SectionKey<BodyParams> kBodySection;
extern const params::SectionKey<ImuParams> kImuSection;

/// The gyro's units for the calibration: the scale and the axis map (validate() refused an axis
/// map that does not parse at start-up; one that does not parse here is the identity).
GyroUnits gyroUnits(const ImuParams& imu);

}  // namespace serial_robot_driver::devices::body
