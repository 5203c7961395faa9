// The servo bus's parameter section (~servo_bus/...): rows in
// src/devices/servo_bus/servo_bus_module.cpp.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::params {

/// The defaults of the bus's core configuration (see kBaseDefaults).
inline const device::ServoBusConfig kServoBusDefaults{};

struct ServoBusParams : DevicePortParams {
  double timeout = std::chrono::duration<double>(kServoBusDefaults.client.timeout).count();  ///< s
  int retries = kServoBusDefaults.client.retries;
  bool allow_dangerous_writes = kServoBusDefaults.client.allow_dangerous_writes;
  std::vector<int> state_ids;     ///< bus servos polled for servo_states (empty: no poll)
  double state_rate = kServoBusDefaults.poll_rate;  ///< Hz, polls of every state_ids servo
  int command_interval_ms = 0;    ///< ROTATE interval for servo_commands without a velocity
  // Bus servos used as named joints (trajectories, servo_states); one entry per joint_ids.
  std::vector<int> joint_ids;
  std::vector<std::string> joint_names;
  std::vector<double> joint_zero_deg;  ///< servo angle at joint position 0; empty: all 0
  std::vector<int> joint_directions;   ///< 1 or -1; empty: all 1
  // Safe motion: servo/relax's DAMPING power; what servos set moving get when the node stops.
  int relax_power_mw = kServoBusDefaults.relax_power_mw;  ///< mW
  std::string on_shutdown = "stop";                       ///< stop | relax | none
  double health_rate = kServoBusDefaults.health_rate;  ///< Hz of the health poll; 0: off
  bool protect = kServoBusDefaults.protect;  ///< relax a servo at its temperature limit
};

}  // namespace serial_robot_driver::params
