// The servo bus's parameter section (~servo_bus/...): rows in
// src/devices/servo_bus/servo_bus_module.cpp.
#pragma once

#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/params/device_sections.h"
#include "serial_robot_driver/params/port_params.h"

namespace serial_robot_driver::devices::servo_bus {

/// The bus's parameters. Those that configure ServoBus are bound straight into `bus`
/// (their defaults are its own; timeout, relax_power_mw and on_shutdown through converted rows,
/// whose checks see the value as written); the rest are the ROS layer's and the checks'.
struct ServoBusParams : params::DevicePortParams {
  /// The bus's configuration as the parameters set it; polled_ids is not a parameter:
  /// makeServoBusConfig (servo_bus_device.h) fills it in from state_ids and joint_ids.
  ServoBusConfig bus;
  std::vector<int> state_ids;   ///< bus servos polled for servo_states (empty: no poll)
  int command_interval_ms = 0;  ///< ROTATE interval for servo_commands without a velocity
  // Bus servos used as named joints (trajectories, servo_states); one entry per joint_ids.
  std::vector<int> joint_ids;
  std::vector<std::string> joint_names;
  std::vector<double> joint_zero_deg;  ///< servo angle at joint position 0; empty: all 0
  std::vector<int> joint_directions;   ///< 1 or -1; empty: all 1
};

/// The key of the bus's section (DeviceModule::sections): params.section(kServoBusSection).
extern const params::SectionKey<ServoBusParams> kServoBusSection;

}  // namespace serial_robot_driver::devices::servo_bus
