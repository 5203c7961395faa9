// The URDF of the configured robot, built from the same parameter file driver_node loads (what
// xacro would do, without xacro): base, two wheels from ~base's geometry, the IMU's link, one
// revolute joint per body joint and per bus-servo joint, each limited to what its servo reaches.
// The robot_description executable prints it; launch/description.launch loads it.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/ros/driver_params.h"

namespace YAML {
class Node;
}

namespace serial_robot_driver::ros_layer {

/// A parameter file (YAML, as `rosparam load` reads it) as a ParamSource, so loadParams gives the
/// driver's own defaults and checks for it. Keys are paths below the file's top level ("base/port").
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

/// A frame parameter as a URDF link name: robot_state_publisher adds the tf_prefix itself, so a
/// leading '/' (which keeps the driver from prefixing) is dropped.
std::string linkName(const std::string& frame);

/// The URDF document. `params` must have passed validate(). Throws ParameterError when two joints
/// or links would share a name.
std::string makeRobotDescription(const DriverParams& params, const ImuMount& imu,
                                 const std::string& robot_name);

}  // namespace serial_robot_driver::ros_layer
