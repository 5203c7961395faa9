// The servo bus's parameter section (~servo_bus/...): rows in
// src/devices/servo_bus/servo_bus_module.cpp.
#pragma once

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::params {

/// The bus's parameters. Those that configure device::ServoBus are bound straight into `bus`
/// (their defaults are its own); the rest are the ROS layer's and the checks'. Three are kept as
/// written, because the core's type could not hold every bad value for the check to name (a
/// sub-millisecond timeout, a negative power, an unknown action); their defaults are the core's.
struct ServoBusParams : DevicePortParams {
  /// The bus's configuration as the parameters set it: client.retries and
  /// .allow_dangerous_writes, poll_rate (~servo_bus/state_rate), health_rate, protect. The rest
  /// (client.timeout, polled_ids, relax_power_mw, on_shutdown) ros_layer::makeServoBusConfig fills
  /// in from the values below.
  device::ServoBusConfig bus;
  /// s to wait for one answer (the core's milliseconds: timeoutMs()).
  double timeout = std::chrono::duration<double>(device::ServoBusOptions{}.timeout).count();
  std::vector<int> state_ids;   ///< bus servos polled for servo_states (empty: no poll)
  int command_interval_ms = 0;  ///< ROTATE interval for servo_commands without a velocity
  // Bus servos used as named joints (trajectories, servo_states); one entry per joint_ids.
  std::vector<int> joint_ids;
  std::vector<std::string> joint_names;
  std::vector<double> joint_zero_deg;  ///< servo angle at joint position 0; empty: all 0
  std::vector<int> joint_directions;   ///< 1 or -1; empty: all 1
  // Safe motion: servo/relax's DAMPING power; what servos set moving get when the node stops.
  int relax_power_mw = device::ServoBusConfig{}.relax_power_mw;  ///< mW
  std::string on_shutdown =
      device::toString(device::ServoBusConfig{}.on_shutdown);  ///< stop | relax | none
  // What every configured servo should report (0: not checked); kept as written, as an int could
  // hold a bad value the core's uint16_t could not.
  int expected_type = 0;
  int expected_firmware = 0;

  /// `timeout` as the bus keeps it: whole milliseconds, rounded.
  std::chrono::milliseconds timeoutMs() const {
    return std::chrono::milliseconds(std::llround(timeout * 1000.0));
  }
};

}  // namespace serial_robot_driver::params
