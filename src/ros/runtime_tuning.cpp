#include "serial_robot_driver/ros/runtime_tuning.h"

#include "serial_robot_driver/TrajectoryTuningConfig.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/tuning_group_server.h"

namespace serial_robot_driver::ros_layer {

RuntimeTuning::RuntimeTuning(const ros::NodeHandle& private_nh, const DriverParams& params,
                             std::vector<core::Device*> devices,
                             trajectory::TrajectoryExecutor* trajectory)
    : in_force_(params), devices_(std::move(devices)), trajectory_(trajectory) {
  // Each enabled device starts its own groups; the trajectory group is the node's.
  for (const RosDeviceModule* module : registeredInterfaces()) {
    if (module->add_tuning && params.enabled(module->name)) {
      module->add_tuning(*this, private_nh, servers_);
    }
  }
  if (trajectory_) {
    addGroupServer<TrajectoryTuningConfig>(*this, private_nh, "trajectory", servers_);
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
  for (const std::string& change : result.changes) {
    ROS_INFO("dynamic_reconfigure: %s", change.c_str());
  }
  if (result.changes.empty()) return in_force_;
  in_force_ = result.applied;
  for (core::Device* device : devices_) device->retune(in_force_);
  if (trajectory_) trajectory_->retune(in_force_.trajectory);
  return in_force_;
}

}  // namespace serial_robot_driver::ros_layer
