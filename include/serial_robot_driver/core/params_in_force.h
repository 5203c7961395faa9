// The parameters in force while the driver runs and the changes made to them at runtime, ROS-free,
// for every front end's tuning (ROS: dynamic_reconfigure, ros/runtime_tuning.h). A change is
// checked as the start-up parameters are (params::tuneParams: a value the check refuses is not
// applied, the value in force stays, with the reason); an accepted change goes to every device's
// retune() and to the trajectories at once, and each device applies it from its next loop tick or
// transaction under its own lock, so no thread sees half of it.
//
// Threading: any thread; mutex_ makes the changes one at a time.
#pragma once

#include <mutex>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/params/driver_params.h"
#include "serial_robot_driver/trajectory/executor.h"

namespace serial_robot_driver::core {

class ParamsInForce {
 public:
  /// `params` are in force now; `devices` and `trajectory` (may be null) get every accepted change
  /// and must outlive this object.
  ParamsInForce(const params::DriverParams& params, std::vector<Device*> devices,
                trajectory::TrajectoryExecutor* trajectory)
      : in_force_(params), devices_(std::move(devices)), trajectory_(trajectory) {}

  /// From now on nothing is applied (the devices are shutting down). Idempotent.
  void stop();
  params::DriverParams inForce() const;
  /// Applies `requested` as far as the checks allow and hands an accepted change to the devices.
  /// The result: the parameters in force afterwards (`applied`), the refusals and the changes
  /// (both empty once stopped).
  params::TuningResult apply(const std::vector<params::ParamAssignment>& requested);

 private:
  mutable std::mutex mutex_;  // guards everything below
  params::DriverParams in_force_;
  bool stopped_ = false;
  const std::vector<Device*> devices_;
  trajectory::TrajectoryExecutor* const trajectory_;
};

}  // namespace serial_robot_driver::core
