// A parameter file (YAML: the `rosparam load` form of config/robot.yaml, the private parameters as
// top-level keys, nested maps for the groups) read through the driver's one parameter table, so
// that robot_description and dds_driver get the node's own defaults and checks. ROS-free; the
// only code that needs yaml-cpp (srd_yaml_params), so the core does not.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/params/driver_params.h"

namespace YAML {
class Node;
}

namespace serial_robot_driver::params {

/// The file as a ParamSource: a key is the path below the top level ("base/wheel_diameter" is
/// `base: {wheel_diameter: ...}`).
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

/// The driver's parameters as the node loads them, from a file: every table key (loadParams, so a
/// key of the wrong type is a ParameterError and `unknown_keys` receives the typos), `tf_prefix`
/// from the file's top level, the frames put under it. Not validated (validate() is the caller's).
/// Throws std::runtime_error for a file that cannot be read.
DriverParams loadParamsFile(const std::string& path, std::vector<std::string>* unknown_keys);

}  // namespace serial_robot_driver::params
