// Runtime tuning: one dynamic_reconfigure server per parameter group, in the group's own namespace
// (~base, ~imu, ...), so `dynparam set /driver_node/base max_wheel_speed 0.5` changes
// ~base/max_wheel_speed. The servers start with the values the node was started with (never the
// .cfg defaults) and write every accepted change back to the parameter server, which therefore
// always holds what is in force.
//
// A change is checked and handed to the devices by the core (core/params_in_force.h): a value the
// check refuses is not applied, the value in force stays (logged once, with the reason) and the
// server's answer shows it. dynamic_reconfigure itself clamps a value outside the .cfg range to
// the range.
//
// Threading: the servers' callbacks run on the node's global callback queue (the node's spinner or
// the nodelet manager's threads); the core makes them one at a time.
#pragma once

#include <ros/node_handle.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/params_in_force.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace serial_robot_driver::ros_layer {

class RuntimeTuning {
 public:
  /// Starts the servers under `private_nh`: each enabled device's (RosDeviceModule::add_tuning:
  /// ~base, ~imu, ~servo_bus) and ~trajectory (`trajectory` not null: some device has joints).
  /// `params` are the parameters in force; `devices` and `trajectory` get every accepted change
  /// and must outlive this object.
  RuntimeTuning(const ros::NodeHandle& private_nh, const DriverParams& params,
                std::vector<core::Device*> devices,
                trajectory::TrajectoryExecutor* trajectory = nullptr);
  ~RuntimeTuning();
  RuntimeTuning(const RuntimeTuning&) = delete;
  RuntimeTuning& operator=(const RuntimeTuning&) = delete;

  /// From now on every request is answered with the values in force, nothing is applied (the
  /// devices are shutting down). Idempotent.
  void stop();

  /// The parameters in force.
  DriverParams inForce() const;

  /// Applies `requested` of the server `group` (tuneParams), logs refusals and changes, hands an
  /// accepted change to the devices. Returns the parameters in force afterwards.
  DriverParams apply(const std::string& group, const std::vector<ParamAssignment>& requested);

  /// One group's dynamic_reconfigure server (ros/tuning_group_server.h), its type erased so the
  /// servers of every group are held in one list.
  class Server {
   public:
    virtual ~Server() = default;
  };
  using Servers = std::vector<std::unique_ptr<Server>>;

 private:
  core::ParamsInForce params_;
  Servers servers_;  // last: destroyed first
};

}  // namespace serial_robot_driver::ros_layer
