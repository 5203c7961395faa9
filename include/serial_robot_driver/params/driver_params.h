// Every parameter of the driver, loaded once at start-up into one struct (names and defaults:
// docs/node_api.md and config/robot.yaml). The table (params/param_table.h) is where each key is
// spelled and bound to its field; validate() throws ParameterError naming the first bad
// parameter, and the node prints it and exits non-zero. ROS-free: the ROS layer only reads the
// parameter server into it (ros/driver_params.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/params/device_sections.h"
#include "serial_robot_driver/params/param_table.h"
#include "serial_robot_driver/params/port_params.h"
#include "serial_robot_driver/trajectory/tolerances.h"
#include "serial_robot_driver/transport/recorded_stream.h"

namespace serial_robot_driver::core {
struct DeviceModule;
}

namespace serial_robot_driver::params {

/// Defaults of follow_joint_trajectory and joint_trajectory (a goal's own tolerances override
/// them): the executor's own, bound straight to the ~trajectory/... rows.
using TrajectoryParams = trajectory::GoalDefaults;

/// ~e_stop: the node's one emergency stop.
struct EStopParams {
  /// The node starts with the e-stop engaged (a respawned driver comes back stopped) until an
  /// e_stop false arrives.
  bool start_engaged = false;
};

/// ~ros2: the same robot also on a ROS 2 graph, through DDS (docs/ros2.md).
struct Ros2Params {
  bool enabled = false;  ///< driver_node serves the ROS 2 graph too (dds_driver always does)
  /// The DDS domain: -1 takes $ROS_DOMAIN_ID (0 when unset), as every ROS 2 node does; else 0..232.
  int domain_id = -1;
  /// Unicast discovery peers (IPv4 addresses or host names) for networks without multicast.
  std::vector<std::string> peers;
};

/// The tf frame name of a frame parameter under `tf_prefix`, as robot_state_publisher resolves its
/// links: "<prefix>/<frame>" with the prefix's own leading and trailing slashes dropped
/// ("/robot1/" and "robot1" alike); a frame written with a leading '/' is taken as it is, without
/// the slash; an empty prefix leaves the frame as configured. The one place a frame name is made.
std::string resolveFrame(const std::string& tf_prefix, const std::string& frame);

struct DriverParams {
  /// Every registered device's sections (DeviceModule::sections) with their defaults.
  DriverParams();

  std::string port = "/dev/ttyUSB0";
  int baud = 115200;
  double loop_rate = 50.0;  ///< Hz: the devices' control loop
  double reconnect_interval = 1.0;
  bool capture = false;      ///< publish every chunk in and out on serial_raw
  /// SCHED_FIFO priority of the threads that carry frames (core/realtime.h), memory locked; 0: off
  int realtime_priority = 0;
  /// µs: the fair scheduler's slice the node's threads ask for (core/scheduler_slice.h); 0: the
  /// kernel's default
  int scheduler_slice_us = 100;
  std::string replay_bag;    ///< non-empty: read the ports from this bag's serial_raw, not the wire
  double replay_rate = 1.0;  ///< replay speed; 0: as fast as possible
  /// Not a parameter: the running replay's timeline (set by the node once the bag is read), which
  /// maps the frames' arrival times back to their recorded stamps.
  std::shared_ptr<const transport::ReplayPacing> replay_timeline;
  /// The devices' own sections (their rows: src/devices/<name>/<name>_module.cpp), reached by
  /// the keys their modules declare: section(kBaseSection).
  DeviceSections sections;
  TrajectoryParams trajectory;
  EStopParams e_stop;
  Ros2Params ros2;
  /// Not a ~ parameter: `tf_prefix` searched upward from the node's namespace (as
  /// robot_state_publisher does), so one value in a robot's namespace serves all its nodes.
  std::string tf_prefix;

  /// The section of `key` (declared by the device that owns it); throws std::logic_error for a
  /// key no registered device lists.
  template <typename Section>
  Section& section(const SectionKey<Section>& key) {
    return sections.get(key);
  }
  template <typename Section>
  const Section& section(const SectionKey<Section>& key) const {
    return sections.get(key);
  }

  /// Puts every device's frame parameters (DeviceModule::resolve_frames) under tf_prefix
  /// (resolveFrame). Loading from the parameter server calls it once, after reading tf_prefix.
  void resolveFrames();

  /// Throws ParameterError naming the first parameter that is out of range or inconsistent.
  void validate() const;

  /// The port parameters (~<name>/enabled, port, baud) of a registered device.
  const DevicePortParams& portParams(const core::DeviceModule& device) const;
  DevicePortParams& portParams(const core::DeviceModule& device);
  bool enabled(const core::DeviceModule& device) const { return portParams(device).enabled; }
  /// Whether the registered device called `name` is enabled (false for an unknown name).
  bool enabled(const std::string& device) const;
  /// The device's own port or baud, or the node-wide one it inherits.
  std::string portOf(const core::DeviceModule& device) const;
  int baudOf(const core::DeviceModule& device) const;
  /// A topic's publisher queue: `live` frames (a slow subscriber drops old ones), but unbounded
  /// while replaying, where a full-speed replay must not lose what subscribers have not read yet.
  int publisherQueue(int live) const { return replay_bag.empty() ? live : 0; }
};

/// Reads every table key present in `source` (missing keys keep their defaults; a key of the
/// wrong type is a ParameterError). `unknown_keys` receives the keys the driver does not know.
/// `extra_known` are keys read elsewhere that are not typos (diagnostic_period, tf_prefix).
DriverParams loadParams(const ParamSource& source, std::vector<std::string>* unknown_keys);

/// One requested value: the parameter's key as in the table ("base/max_wheel_speed") and the value.
using ParamAssignment = std::pair<std::string, ParamValue>;

struct TuningResult {
  DriverParams applied;  ///< the parameters in force after the change (they pass validate())
  /// One line per refused value: which, why (validate()'s message) and the value kept instead.
  std::vector<std::string> refusals;
  /// One line per requested value that applies and differs from the value in force, in request
  /// order: "~base/max_wheel_speed = 0.5 (was 1)". Empty: nothing changes (nothing to retune).
  std::vector<std::string> changes;
};

/// The parameters `in_force` with `requested` applied, as far as validate() accepts them: a
/// refused value is dropped (the value in force is kept). When validate() names a parameter that
/// was not changed (a rule between several values), every changed value of the request is
/// refused. Throws std::invalid_argument for a key that is not in the table or a value of the wrong
/// type (a programming error: the .cfg files and the table agree, see test_runtime_tuning.cpp).
TuningResult tuneParams(const DriverParams& in_force,
                        const std::vector<ParamAssignment>& requested);

}  // namespace serial_robot_driver::params
