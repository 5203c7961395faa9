// The URDF of the configured robot, built from the same parameter file driver_node loads (what
// xacro would do, without xacro): base, two wheels from ~base's geometry, the IMU's link, one
// revolute joint per servo joint, each limited to what its servo reaches. ROS-free: the YAML file
// is read with yaml-cpp, the URDF is text; serial_robot_driver/ros/robot_description.h adds the
// servo joints the ROS layer derives from the parameters.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

// DriverParams and ParamSource: the parameter table, on its way into the core.
#include "serial_robot_driver/ros/driver_params.h"

namespace YAML {
class Node;
}

namespace serial_robot_driver::description {

using ros_layer::DriverParams;
using ros_layer::ParameterError;
using ros_layer::ParamSource;
using ros_layer::ParamValue;

/// A parameter file (YAML, as `rosparam load` reads it) as a ParamSource, so loadParams gives the
/// driver's own defaults and checks for it. Keys are paths below the file's top level
/// ("base/port").
class YamlParamSource : public ParamSource {
 public:
  /// Throws std::runtime_error when the file cannot be read or is not a YAML mapping.
  explicit YamlParamSource(const std::string& path);
  ~YamlParamSource() override;

  bool has(const std::string& key) const override;
  bool get(const std::string& key, ParamValue* value) const override;
  std::vector<std::string> keys() const override;

 private:
  std::unique_ptr<YAML::Node> root_;
};

/// Where the IMU sits on the base (the `imu_xyz` / `imu_rpy` args of the launch files).
struct ImuMount {
  std::array<double, 3> xyz{0, 0, 0};  ///< m in the base frame
  std::array<double, 3> rpy{0, 0, 0};  ///< rad, URDF order (roll, pitch, yaw)
};

/// A revolute servo joint with its reachable range.
struct ServoJoint {
  std::string name;
  std::string key;  ///< the parameter that names it, for errors
  double lower, upper;
  double velocity;  ///< rad/s limit
};

/// A frame parameter as a URDF link name: robot_state_publisher adds the tf_prefix itself, so a
/// leading '/' (which keeps the driver from prefixing) is dropped.
std::string linkName(const std::string& frame);

/// The URDF document: the base and IMU from `params` (which must have passed validate()), then
/// `servos` in a row across the chassis. Throws ParameterError when two joints or links would
/// share a name.
std::string makeRobotDescription(const DriverParams& params, const std::vector<ServoJoint>& servos,
                                 const ImuMount& imu, const std::string& robot_name);

}  // namespace serial_robot_driver::description
