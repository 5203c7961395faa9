// The dynamic_reconfigure server of one tuning group, for a device's RosDeviceModule::add_tuning
// (src/devices/<name>/ros/) and the node's own ~trajectory group (runtime_tuning.cpp).
#pragma once

#include <dynamic_reconfigure/config_tools.h>
#include <dynamic_reconfigure/server.h>

#include <boost/any.hpp>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "serial_robot_driver/ros/runtime_tuning.h"

namespace serial_robot_driver::ros_layer {

/// The server of one group, `Config` generated from the group's <Group>Tuning.cfg: each of its
/// parameters is the table's "<group>/<name>". It answers with what RuntimeTuning::apply() leaves
/// in force.
template <typename Config>
class GroupServer : public RuntimeTuning::Server {
 public:
  GroupServer(RuntimeTuning& owner, const ros::NodeHandle& private_nh, const std::string& group)
      : owner_(owner), group_(group), server_(server_mutex_, ros::NodeHandle(private_nh, group)) {
    // The server starts from the parameter server and the .cfg defaults; what applies is what
    // the node was started with (the parameter server may lack a key the node took as default).
    Config initial = Config::__getDefault__();
    write(owner_.inForce(), initial);
    server_.updateConfig(initial);
    server_.setCallback([this](Config& config, uint32_t) { onRequest(config); });
  }

 private:
  // The types a .cfg parameter can have (the table's lists cannot be tuned).
  template <typename T>
  static constexpr bool kScalar = std::is_same_v<T, bool> || std::is_same_v<T, int> ||
                                  std::is_same_v<T, double> || std::is_same_v<T, std::string>;

  void onRequest(Config& config) {
    std::vector<ParamAssignment> requested;
    const DriverParams before = owner_.inForce();
    for (const auto& description : Config::__getParamDescriptions__()) {
      const std::string key = group_ + "/" + description->name;
      boost::any any;
      description->getValue(config, any);
      ParamValue value = params::specFor(key).get(before);
      std::visit(
          [&any](auto& typed) {
            using T = std::decay_t<decltype(typed)>;
            if constexpr (kScalar<T>) typed = boost::any_cast<T>(any);
          },
          value);
      requested.emplace_back(key, value);
    }
    // The answer (and the parameter server) show what applies.
    write(owner_.apply(group_, requested), config);
  }

  /// Sets every parameter of `config` to its value in `params`.
  void write(const DriverParams& params, Config& config) const {
    dynamic_reconfigure::Config message;
    for (const auto& description : Config::__getParamDescriptions__()) {
      std::visit(
          [&](const auto& typed) {
            using T = std::decay_t<decltype(typed)>;
            if constexpr (kScalar<T>) {
              dynamic_reconfigure::ConfigTools::appendParameter(message, description->name, typed);
            }
          },
          params::specFor(group_ + "/" + description->name).get(params));
    }
    for (const auto& description : Config::__getParamDescriptions__()) {
      description->fromMessage(message, config);
    }
  }

  RuntimeTuning& owner_;
  const std::string group_;
  boost::recursive_mutex server_mutex_;  // the server's; ours, so updateConfig() may use it
  dynamic_reconfigure::Server<Config> server_;
};

/// Starts the server of `group` (its parameters: `Config`) into `servers`.
template <typename Config>
void addGroupServer(RuntimeTuning& tuning, const ros::NodeHandle& private_nh,
                    const std::string& group, RuntimeTuning::Servers& servers) {
  servers.push_back(std::make_unique<GroupServer<Config>>(tuning, private_nh, group));
}

}  // namespace serial_robot_driver::ros_layer
