#include "serial_robot_driver/ros/driver_params.h"

#include <ros/node_handle.h>
#include <ros/param.h>

namespace serial_robot_driver::ros_layer {

namespace {

/// The parameter server under the node's private namespace.
class NodeHandleSource : public ParamSource {
 public:
  explicit NodeHandleSource(const ros::NodeHandle& nh) : nh_(nh) {}

  bool has(const std::string& key) const override { return nh_.hasParam(key); }

  bool get(const std::string& key, ParamValue* value) const override {
    return std::visit([&](auto& typed) { return nh_.getParam(key, typed); }, *value);
  }

  std::vector<std::string> keys() const override {
    std::vector<std::string> all;
    ros::param::getParamNames(all);
    const std::string prefix = nh_.getNamespace() + "/";
    std::vector<std::string> under;
    for (const auto& full : all) {
      if (full.compare(0, prefix.size(), prefix) == 0) under.push_back(full.substr(prefix.size()));
    }
    return under;
  }

 private:
  const ros::NodeHandle& nh_;
};

}  // namespace

DriverParams loadParams(const ros::NodeHandle& nh, std::vector<std::string>* unknown_keys) {
  DriverParams params = params::loadParams(NodeHandleSource(nh), unknown_keys);
  // ~tf_prefix, then tf_prefix in each enclosing namespace up to the root.
  std::string key;
  if (nh.searchParam("tf_prefix", key) && !nh.getParam(key, params.tf_prefix)) {
    throw ParameterError("tf_prefix", "must be a string (found " + key + ")");
  }
  params.resolveFrames();
  return params;
}

}  // namespace serial_robot_driver::ros_layer
