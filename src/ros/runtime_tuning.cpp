#include "serial_robot_driver/ros/runtime_tuning.h"

#include "serial_robot_driver/TrajectoryTuningConfig.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::ros_layer {

RuntimeTuning::RuntimeTuning(const ros::NodeHandle& private_nh, const DriverParams& params,
                             std::vector<core::Device*> devices,
                             trajectory::TrajectoryExecutor* trajectory)
    : params_(params, std::move(devices), trajectory) {
  // Each enabled device starts its own groups; the trajectory group is the node's.
  for (const RosDeviceModule* module : registeredInterfaces()) {
    if (module->add_tuning && params.enabled(module->name)) {
      module->add_tuning(*this, private_nh, servers_);
    }
  }
  if (trajectory) {
    addGroupServer<TrajectoryTuningConfig>(*this, private_nh, "trajectory", servers_);
  }
}

RuntimeTuning::~RuntimeTuning() {
  stop();
  servers_.clear();
}

void RuntimeTuning::stop() { params_.stop(); }

DriverParams RuntimeTuning::inForce() const { return params_.inForce(); }

DriverParams RuntimeTuning::apply(const std::string& group,
                                  const std::vector<ParamAssignment>& requested) {
  const TuningResult result = params_.apply(requested);
  for (const std::string& refusal : result.refusals) {
    ROS_WARN("dynamic_reconfigure ~%s: %s", group.c_str(), refusal.c_str());
  }
  for (const std::string& change : result.changes) {
    ROS_INFO("dynamic_reconfigure: %s", change.c_str());
  }
  return result.applied;
}

}  // namespace serial_robot_driver::ros_layer
