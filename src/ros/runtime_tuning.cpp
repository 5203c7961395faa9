#include "serial_robot_driver/ros/runtime_tuning.h"

#include <dynamic_reconfigure/config_tools.h>
#include <dynamic_reconfigure/server.h>

#include <boost/any.hpp>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "serial_robot_driver/BaseTuningConfig.h"
#include "serial_robot_driver/ImuTuningConfig.h"
#include "serial_robot_driver/ServoBusTuningConfig.h"
#include "serial_robot_driver/TrajectoryTuningConfig.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/trajectory_server.h"

namespace serial_robot_driver::ros_layer {

namespace {

using params::specFor;

template <typename T>
constexpr bool kScalar = std::is_same_v<T, bool> || std::is_same_v<T, int> ||
                         std::is_same_v<T, double> || std::is_same_v<T, std::string>;

}  // namespace

/// One group's server: its type erased, so RuntimeTuning holds them in one list.
class RuntimeTuning::Server {
 public:
  virtual ~Server() = default;
};

namespace {

/// The dynamic_reconfigure server of one group, `Config` generated from cfg/<Group>Tuning.cfg:
/// each of its parameters is the table's "<group>/<name>".
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
  void onRequest(Config& config) {
    std::vector<ParamAssignment> requested;
    const DriverParams before = owner_.inForce();
    for (const auto& description : Config::__getParamDescriptions__()) {
      const std::string key = group_ + "/" + description->name;
      boost::any any;
      description->getValue(config, any);
      ParamValue value = specFor(key).get(before);
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
          specFor(group_ + "/" + description->name).get(params));
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

}  // namespace

RuntimeTuning::RuntimeTuning(const ros::NodeHandle& private_nh, const DriverParams& params,
                             std::vector<DeviceInterface*> devices, TrajectoryServer* trajectory)
    : in_force_(params), devices_(std::move(devices)), trajectory_(trajectory) {
  if (params.base.enabled) {
    servers_.push_back(std::make_unique<GroupServer<BaseTuningConfig>>(*this, private_nh, "base"));
  }
  if (params.body.enabled) {
    servers_.push_back(std::make_unique<GroupServer<ImuTuningConfig>>(*this, private_nh, "imu"));
  }
  if (params.servo_bus.enabled) {
    servers_.push_back(
        std::make_unique<GroupServer<ServoBusTuningConfig>>(*this, private_nh, "servo_bus"));
  }
  if (trajectory_) {
    servers_.push_back(
        std::make_unique<GroupServer<TrajectoryTuningConfig>>(*this, private_nh, "trajectory"));
  }
}

RuntimeTuning::~RuntimeTuning() {
  stop();
  servers_.clear();
}

void RuntimeTuning::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stopped_ = true;
}

DriverParams RuntimeTuning::inForce() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return in_force_;
}

DriverParams RuntimeTuning::apply(const std::string& group,
                                  const std::vector<ParamAssignment>& requested) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopped_) return in_force_;
  const TuningResult result = tuneParams(in_force_, requested);
  for (const std::string& refusal : result.refusals) {
    ROS_WARN("dynamic_reconfigure ~%s: %s", group.c_str(), refusal.c_str());
  }
  bool changed = false;
  for (const auto& [key, value] : requested) {
    const ParamSpec& spec = specFor(key);
    const ParamValue now = spec.get(result.applied);
    if (now == spec.get(in_force_)) continue;
    ROS_INFO("dynamic_reconfigure: ~%s = %s (was %s)", key.c_str(), toText(now).c_str(),
             toText(spec.get(in_force_)).c_str());
    changed = true;
  }
  if (!changed) return in_force_;
  in_force_ = result.applied;
  for (DeviceInterface* device : devices_) device->retune(in_force_);
  if (trajectory_) trajectory_->retune(in_force_.trajectory);
  return in_force_;
}

}  // namespace serial_robot_driver::ros_layer
