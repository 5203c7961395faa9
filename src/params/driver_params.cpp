#include "serial_robot_driver/params/driver_params.h"

#include <set>
#include <stdexcept>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/core/scheduler_slice.h"

namespace serial_robot_driver::params {

namespace {

/// The node-wide rows (the devices add theirs: DeviceModule::add_parameters).
void addNodeParameters(std::vector<ParamSpec>& table) {
  using P = DriverParams;
  const auto node = [&table](const char* key, auto P::*field, auto rule) {
    using T = std::remove_reference_t<decltype(std::declval<P&>().*field)>;
    table.push_back(makeRow<T>(
        key, "", [field](P& p) -> T& { return p.*field; }, Rule<T>(rule)));
  };
  node("port", &P::port, portPath);
  node("baud", &P::baud, baudRate);
  node("loop_rate", &P::loop_rate, [](const double& v, const std::string& key) {
    positiveNumber(v, key);
    require(v <= 1000, key, "must be at most 1000 Hz");
  });
  node("reconnect_interval", &P::reconnect_interval, positiveNumber);
  node("capture", &P::capture, Rule<bool>{});
  node("realtime_priority", &P::realtime_priority, [](const int& v, const std::string& key) {
    require(v >= 0 && v <= core::kMaxRealtimePriority, key,
            "must be 0 (off) or a SCHED_FIFO priority 1.." +
                std::to_string(core::kMaxRealtimePriority));
  });
  node("scheduler_slice_us", &P::scheduler_slice_us, [](const int& v, const std::string& key) {
    require(v == 0 || (v >= core::kMinSchedulerSliceUs && v <= core::kMaxSchedulerSliceUs), key,
            "must be 0 (the kernel's slice) or " + std::to_string(core::kMinSchedulerSliceUs) +
                ".." + std::to_string(core::kMaxSchedulerSliceUs) + " us (got " +
                std::to_string(v) + ")");
  });
  node("replay_bag", &P::replay_bag, Rule<std::string>{});
  node("replay_rate", &P::replay_rate, nonNegativeNumber);
}

/// Trajectory defaults (follow_joint_trajectory, joint_trajectory): node-wide, used by every
/// device with joints.
void addTrajectoryParameters(std::vector<ParamSpec>& table) {
  SectionRows<TrajectoryParams>(table, "", "trajectory",
                                [](DriverParams& p) -> TrajectoryParams& { return p.trajectory; })
      .add("goal_tolerance", &TrajectoryParams::goal_tolerance, nonNegativeNumber)
      .add("goal_time_tolerance", &TrajectoryParams::goal_time_tolerance, nonNegativeNumber)
      .add("path_tolerance", &TrajectoryParams::path_tolerance, nonNegativeNumber)
      .add("max_velocity", &TrajectoryParams::max_velocity, nonNegativeNumber)
      .add("max_start_delay", &TrajectoryParams::max_start_delay, positiveNumber);
}

/// ~ros2: the DDS front end (driver_node's ROS 2 graph; dds_driver reads the same rows).
void addRos2Parameters(std::vector<ParamSpec>& table) {
  SectionRows<Ros2Params>(table, "", "ros2", [](DriverParams& p) -> Ros2Params& { return p.ros2; })
      .add("enabled", &Ros2Params::enabled)
      .add("domain_id", &Ros2Params::domain_id,
           [](const int& value, const std::string& key) {
             // 232: the highest domain whose ports fit below 65536 (ROS 2's own limit).
             require(value == -1 || (value >= 0 && value <= 232), key,
                     "must be -1 ($ROS_DOMAIN_ID) or a domain 0..232 (got " +
                         std::to_string(value) + ")");
           })
      .add("peers", &Ros2Params::peers, networkHosts);
}

std::vector<ParamSpec> buildTable() {
  std::vector<ParamSpec> table;
  addNodeParameters(table);
  SectionRows<EStopParams>(table, "", "e_stop", [](DriverParams& p) -> EStopParams& {
    return p.e_stop;
  }).add("start_engaged", &EStopParams::start_engaged);
  addRos2Parameters(table);
  for (const core::DeviceModule* device : core::registeredDevices()) {
    // Every device's port parameters, then its own.
    const auto port = [device](DriverParams& p) -> DevicePortParams& {
      return p.portParams(*device);
    };
    SectionRows<DevicePortParams>(table, device->name, device->name, port)
        .add("enabled", &DevicePortParams::enabled)
        .add("port", &DevicePortParams::port, portOrInherit)
        .add("baud", &DevicePortParams::baud, baudOrInherit);
    if (device->add_parameters) device->add_parameters(table);
  }
  addTrajectoryParameters(table);
  std::set<std::string> keys;
  for (const ParamSpec& spec : table) {
    if (!keys.insert(spec.key).second) {
      throw std::logic_error("parameter ~" + spec.key + " is in the table twice");
    }
  }
  return table;
}

}  // namespace

bool isChecked(const DriverParams& p, const std::string& device) {
  return device.empty() || p.enabled(device);
}

const std::vector<ParamSpec>& parameterTable() {
  static const std::vector<ParamSpec> table = buildTable();
  return table;
}

std::string resolveFrame(const std::string& tf_prefix, const std::string& frame) {
  if (!frame.empty() && frame[0] == '/') return frame.substr(1);
  const std::size_t first = tf_prefix.find_first_not_of('/');
  if (first == std::string::npos) return frame;  // empty, or nothing but slashes
  const std::size_t last = tf_prefix.find_last_not_of('/');
  return tf_prefix.substr(first, last - first + 1) + "/" + frame;
}

DriverParams::DriverParams() {
  for (const core::DeviceModule* device : core::registeredDevices()) {
    for (const AnySectionKey* key : device->sections) sections.add(*key);
  }
}

void DriverParams::resolveFrames() {
  for (const core::DeviceModule* device : core::registeredDevices()) {
    if (device->resolve_frames) device->resolve_frames(*this);
  }
}

const DevicePortParams& DriverParams::portParams(const core::DeviceModule& device) const {
  return sections.portParams(device.name);
}

DevicePortParams& DriverParams::portParams(const core::DeviceModule& device) {
  return sections.portParams(device.name);
}

bool DriverParams::enabled(const std::string& name) const {
  const core::DeviceModule* device = core::findDevice(name);
  return device != nullptr && enabled(*device);
}

std::string DriverParams::portOf(const core::DeviceModule& device) const {
  const DevicePortParams& own = portParams(device);
  return own.port.empty() ? port : own.port;
}

int DriverParams::baudOf(const core::DeviceModule& device) const {
  const DevicePortParams& own = portParams(device);
  return own.baud > 0 ? own.baud : baud;
}

void DriverParams::validate() const {
  // Single values first (the table; a device's only while it is enabled), then what relates
  // several parameters.
  for (const auto& spec : parameterTable()) {
    if (isChecked(*this, spec.device)) spec.check(*this);
  }

  require(tf_prefix.find(' ') == std::string::npos, "tf_prefix", "must not contain spaces");
  require(!capture || replay_bag.empty(), "capture",
          "cannot be combined with ~replay_bag: a replay reads a capture and writes nothing");
  const auto& devices = core::registeredDevices();
  std::string all_devices;
  bool any_enabled = false;
  for (const core::DeviceModule* device : devices) {
    all_devices += (all_devices.empty() ? "" : ", ") + std::string(device->name);
    any_enabled |= enabled(*device);
  }
  require(any_enabled, std::string(devices.front()->name) + "/enabled",
          "every device is disabled (" + all_devices + "): nothing to drive");
  for (const core::DeviceModule* device : devices) {
    if (enabled(*device) && device->validate) device->validate(*this);
  }

  // Devices sharing a path share one port, so they must agree on its baud rate.
  struct Use {
    std::string name, path;
    int baud;
  };
  std::vector<Use> uses;
  for (const core::DeviceModule* device : devices) {
    if (!enabled(*device)) continue;
    uses.push_back({device->name, portOf(*device), baudOf(*device)});
  }
  for (std::size_t i = 0; i < uses.size(); ++i) {
    for (std::size_t j = i + 1; j < uses.size(); ++j) {
      require(uses[i].path != uses[j].path || uses[i].baud == uses[j].baud, uses[j].name + "/baud",
              "differs from " + uses[i].name + "'s baud on the shared port " + uses[i].path);
    }
  }
}

DriverParams loadParams(const ParamSource& source, std::vector<std::string>* unknown_keys) {
  DriverParams params;
  // diagnostic_period: read by diagnostic_updater itself; tf_prefix: searched for, may be private.
  std::set<std::string> known = {"diagnostic_period", "tf_prefix"};
  for (const auto& spec : parameterTable()) {
    known.insert(spec.key);
    if (!source.has(spec.key)) continue;
    ParamValue value = spec.get(params);
    // A present key of the wrong type is an error, not a silent default.
    if (!source.get(spec.key, &value)) throw ParameterError(spec.key, "must be " + typeName(value));
    spec.set(params, value);
  }
  if (unknown_keys) {
    unknown_keys->clear();
    for (const auto& key : source.keys()) {
      if (!known.count(key)) unknown_keys->push_back(key);
    }
  }
  return params;
}

namespace {

/// One tuneParams call: applies the request, then refuses what validate() rejects, round by round.
class TuningRun {
 public:
  TuningRun(const DriverParams& in_force, const std::vector<ParamAssignment>& requested)
      : in_force_(in_force), requested_(requested), result_{in_force, {}, {}} {}

  TuningResult run() {
    applyRequested();
    // Each round refuses at least one changed value, and `in_force` itself passes validate().
    for (std::size_t round = 0; round <= requested_.size(); ++round) {
      try {
        result_.applied.validate();
        describeChanges();
        return result_;
      } catch (const ParameterError& error) {
        refuseFor(error);
      }
    }
    result_.applied.validate();  // unreachable unless `in_force` was invalid: throws then
    describeChanges();
    return result_;
  }

 private:
  void applyRequested() {
    for (const auto& [key, value] : requested_) {
      const ParamSpec& spec = specFor(key);
      if (spec.get(in_force_).index() != value.index()) {
        throw std::invalid_argument("~" + key + ": the value has another type than the parameter");
      }
      try {
        spec.set(result_.applied, value);
      } catch (const ParameterError& error) {
        addRefusal(key, value, error.what());  // a converted row's check: the field keeps its value
      }
    }
  }

  /// Refuses the value validate() named when the request changed it, else every changed value.
  void refuseFor(const ParameterError& error) {
    bool named_value_changed = false;
    for (const auto& [key, value] : requested_) {
      if (key == error.name() && changed(key)) named_value_changed = true;
    }
    if (named_value_changed) {
      refuse(error.name(), error.what());
      return;
    }
    // A rule between several values, broken by the change: refuse all of it.
    for (const auto& [key, value] : requested_) {
      if (changed(key)) refuse(key, error.what());
    }
  }

  bool changed(const std::string& key) const {
    const ParamSpec& spec = specFor(key);
    return spec.get(result_.applied) != spec.get(in_force_);
  }

  void addRefusal(const std::string& key, const ParamValue& value, const std::string& why) {
    result_.refusals.push_back("~" + key + " = " + toText(value) + " refused (" + why +
                               "); keeping " + toText(specFor(key).get(in_force_)));
  }

  void refuse(const std::string& key, const std::string& why) {
    const ParamSpec& spec = specFor(key);
    addRefusal(key, spec.get(result_.applied), why);
    spec.set(result_.applied, spec.get(in_force_));
  }

  void describeChanges() {
    for (const auto& [key, value] : requested_) {
      const ParamSpec& spec = specFor(key);
      const ParamValue now = spec.get(result_.applied);
      if (now == spec.get(in_force_)) continue;
      result_.changes.push_back("~" + key + " = " + toText(now) + " (was " +
                                toText(spec.get(in_force_)) + ")");
    }
  }

  const DriverParams& in_force_;
  const std::vector<ParamAssignment>& requested_;
  TuningResult result_;
};

}  // namespace

TuningResult tuneParams(const DriverParams& in_force,
                        const std::vector<ParamAssignment>& requested) {
  return TuningRun(in_force, requested).run();
}

}  // namespace serial_robot_driver::params
