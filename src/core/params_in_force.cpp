#include "serial_robot_driver/core/params_in_force.h"

namespace serial_robot_driver::core {

void ParamsInForce::stop() {
  std::lock_guard<std::mutex> lock(mutex_);
  stopped_ = true;
}

params::DriverParams ParamsInForce::inForce() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return in_force_;
}

params::TuningResult ParamsInForce::apply(const std::vector<params::ParamAssignment>& requested) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopped_) return {in_force_, {}, {}};
  params::TuningResult result = params::tuneParams(in_force_, requested);
  if (result.changes.empty()) {
    result.applied = in_force_;
    return result;
  }
  in_force_ = result.applied;
  for (Device* device : devices_) device->retune(in_force_);
  if (trajectory_) trajectory_->retune(in_force_.trajectory);
  return result;
}

}  // namespace serial_robot_driver::core
