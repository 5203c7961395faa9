#include "serial_robot_driver/ros/driver_params.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <type_traits>

#include <ros/node_handle.h>
#include <ros/param.h>

#include "serial_robot_driver/protocol/body_codec.h"
#include "serial_robot_driver/transport/serial_port.h"

namespace serial_robot_driver::ros_layer {

namespace {

void require(bool ok, const std::string& name, const std::string& problem) {
  if (!ok) throw ParameterError(name, problem);
}

void requirePositive(double value, const std::string& name) {
  std::ostringstream text;
  text << "must be a finite number > 0 (got " << value << ")";
  require(std::isfinite(value) && value > 0, name, text.str());
}

void requireNonNegative(double value, const std::string& name) {
  std::ostringstream text;
  text << "must be a finite number >= 0 (got " << value << ")";
  require(std::isfinite(value) && value >= 0, name, text.str());
}

void requireBaud(int baud, const std::string& name, bool zero_means_inherit) {
  if (zero_means_inherit && baud == 0) return;
  // The port's own table: a rate passes here exactly when the port can open at it.
  require(baud > 0 && transport::isSupportedBaud(static_cast<unsigned>(baud)), name,
          "unsupported baud rate " + std::to_string(baud) + " (supported: " +
              transport::supportedBaudRatesText() + ")");
}

// --- the table -------------------------------------------------------------------------------

/// A range check of one field's value; throws ParameterError naming `key`.
template <typename T>
using Rule = std::function<void(const T& value, const std::string& key)>;

template <typename T>
struct NoDeduce {
  using type = T;
};

template <typename T>
void positive(const T& value, const std::string& key) {
  requirePositive(value, key);
}

/// A list of bus servo ids: each addressable (255 is the broadcast address), none twice.
void busServoIds(const std::vector<int>& ids, const std::string& key) {
  std::set<int> seen;
  for (int id : ids) {
    require(id >= 0 && id <= 254, key,
            "ids must be 0..254 (255 is broadcast), got " + std::to_string(id));
    require(seen.insert(id).second, key, "id " + std::to_string(id) + " is listed twice");
  }
}

template <typename T>
void nonNegative(const T& value, const std::string& key) {
  requireNonNegative(value, key);
}

void baud(const int& value, const std::string& key) { requireBaud(value, key, false); }

void percent(const int& value, const std::string& key) {
  require(value >= 0 && value <= 100, key, "must be 0..100 (got " + std::to_string(value) + ")");
}

void direction(const int& value, const std::string& key) {
  require(
      value == 1 || value == -1, key,
      "must be 1 or -1 (got " + std::to_string(value) + "); -1 flips a wheel that drives backward");
}

void frameId(const std::string& value, const std::string& key) {
  require(!value.empty(), key, "must name a tf frame");
  require(value.find(' ') == std::string::npos, key, "must not contain spaces");
}
void baudOrInherit(const int& value, const std::string& key) { requireBaud(value, key, true); }

/// Whether a key's range check applies: a device's keys (and the IMU's, which the body reports)
/// are checked only while that device is enabled.
bool checked(const DriverParams& p, const std::string& key) {
  const std::string prefix = key.substr(0, key.find('/'));
  if (prefix == "imu") return p.enabled(device::DeviceKind::kBody);
  for (const device::DeviceDescription& device : device::deviceSet()) {
    if (prefix == device.name) return p.enabled(device.kind);
  }
  return true;
}

template <typename T, typename Access>
ParamSpec makeSpec(const char* key, Access access, Rule<T> rule) {
  ParamSpec spec;
  spec.key = key;
  spec.get = [access](const DriverParams& p) {
    return ParamValue(access(const_cast<DriverParams&>(p)));
  };
  spec.set = [access](DriverParams& p, const ParamValue& value) {
    access(p) = std::get<T>(value);
  };
  spec.check = [access, rule, name = std::string(key)](const DriverParams& p) {
    if (rule && checked(p, name)) rule(access(const_cast<DriverParams&>(p)), name);
  };
  return spec;
}

/// A node-wide key: `row("loop_rate", &DriverParams::loop_rate, positive<double>)`.
template <typename T>
ParamSpec row(const char* key, T DriverParams::*field, typename NoDeduce<Rule<T>>::type rule = {}) {
  return makeSpec<T>(key, [field](DriverParams& p) -> T& { return p.*field; }, rule);
}

/// A key of one section: `row("base/pid_rate", &DriverParams::base, &BaseParams::pid_rate, ...)`.
template <typename Section, typename Owner, typename T>
ParamSpec row(const char* key, Section DriverParams::*section, T Owner::*field,
              typename NoDeduce<Rule<T>>::type rule = {}) {
  static_assert(std::is_base_of_v<Owner, Section>, "the field must belong to the section");
  return makeSpec<T>(
      key, [section, field](DriverParams& p) -> T& { return static_cast<Owner&>(p.*section).*field; },
      rule);
}

std::vector<ParamSpec> buildTable() {
  using P = DriverParams;
  using Base = BaseParams;
  using Body = BodyParams;
  using Imu = ImuParams;
  using Bus = ServoBusParams;
  using Port = DevicePortParams;
  return {
      row("port", &P::port,
          [](const std::string& v, const std::string& key) {
            require(!v.empty(), key, "must name a serial device, e.g. /dev/ttyUSB0");
          }),
      row("baud", &P::baud, baud),
      row("loop_rate", &P::loop_rate,
          [](const double& v, const std::string& key) {
            requirePositive(v, key);
            require(v <= 1000, key, "must be at most 1000 Hz");
          }),
      row("reconnect_interval", &P::reconnect_interval, positive<double>),
      row("capture", &P::capture),
      row("replay_bag", &P::replay_bag),
      row("replay_rate", &P::replay_rate, nonNegative<double>),

      row("base/enabled", &P::base, &Port::enabled),
      row("base/port", &P::base, &Port::port),
      row("base/baud", &P::base, &Port::baud, baudOrInherit),
      row("base/wheel_diameter", &P::base, &Base::wheel_diameter, positive<double>),
      row("base/encoder_resolution", &P::base, &Base::encoder_resolution, positive<int>),
      row("base/pid_rate", &P::base, &Base::pid_rate, positive<double>),
      row("base/wheel_separation", &P::base, &Base::wheel_separation, positive<double>),
      // > 0: there is no "no limit" value. No maximum: the base's top speed is not documented, and
      // the speed field's own range (int16 ticks per PID period) depends on tunable geometry.
      row("base/max_wheel_speed", &P::base, &Base::max_wheel_speed, positive<double>),
      row("base/max_wheel_accel", &P::base, &Base::max_wheel_accel, nonNegative<double>),
      row("base/cmd_vel_timeout", &P::base, &Base::cmd_vel_timeout, positive<double>),
      row("base/speed_dithering", &P::base, &Base::speed_dithering),
      row("base/battery_poll_rate", &P::base, &Base::battery_poll_rate, nonNegative<double>),
      row("base/battery_warn_percent", &P::base, &Base::battery_warn_percent, percent),
      row("base/battery_error_percent", &P::base, &Base::battery_error_percent, percent),
      row("base/odom_frame", &P::base, &Base::odom_frame, frameId),
      row("base/base_frame", &P::base, &Base::base_frame, frameId),
      row("base/publish_tf", &P::base, &Base::publish_tf),
      row("base/left_wheel_direction", &P::base, &Base::left_wheel_direction, direction),
      row("base/right_wheel_direction", &P::base, &Base::right_wheel_direction, direction),
      row("base/left_wheel_joint", &P::base, &Base::left_wheel_joint, frameId),
      row("base/right_wheel_joint", &P::base, &Base::right_wheel_joint, frameId),
      row("base/use_imu_heading", &P::base, &Base::use_imu_heading),

      row("body/enabled", &P::body, &Port::enabled),
      row("body/port", &P::body, &Port::port),
      row("body/baud", &P::body, &Port::baud, baudOrInherit),
      row("body/servo_ids", &P::body, &Body::servo_ids,
          [](const std::vector<int>& ids, const std::string& key) {
            require(!ids.empty(), key, "must list at least one servo id");
            require(ids.size() <= protocol::body::kMaxTelemetryServos, key,
                    "at most " + std::to_string(protocol::body::kMaxTelemetryServos) +
                        " servos fit in a telemetry frame");
            std::set<int> seen;
            for (int id : ids) {
              // 253 = FD would put FF FF FD, the sync-write header, inside a sync-write frame.
              require(id >= 0 && id <= 252, key,
                      "ids must be 0..252 (253 would look like a frame header, 254 is broadcast), "
                      "got " + std::to_string(id));
              require(seen.insert(id).second, key, "id " + std::to_string(id) + " is listed twice");
            }
          }),
      row("body/joint_names", &P::body, &Body::joint_names,
          [](const std::vector<std::string>& names, const std::string& key) {
            std::set<std::string> seen;
            for (const auto& name : names) {
              require(!name.empty(), key, "a joint name is empty");
              require(seen.insert(name).second, key, "'" + name + "' is listed twice");
            }
          }),
      row("body/ticks_per_revolution", &P::body, &Body::ticks_per_revolution,
          [](const int& v, const std::string& key) { require(v > 0, key, "must be > 0"); }),
      row("body/zero_ticks", &P::body, &Body::zero_ticks,
          [](const std::vector<int>& zeros, const std::string& key) {
            for (int zero : zeros)
              require(zero >= 0 && zero <= 65535, key, "entries must be 0..65535");
          }),
      row("body/directions", &P::body, &Body::directions,
          [](const std::vector<int>& directions, const std::string& key) {
            for (int d : directions) require(d == 1 || d == -1, key, "entries must be 1 or -1");
          }),
      row("body/velocity_scale", &P::body, &Body::velocity_scale, nonNegative<double>),

      row("imu/frame_id", &P::imu, &Imu::frame_id,
          [](const std::string& v, const std::string& key) {
            require(!v.empty(), key, "must not be empty");
          }),
      row("imu/axis_map", &P::imu, &Imu::axis_map,
          [](const std::vector<std::string>& entries, const std::string& key) {
            std::string problem;
            require(parseAxisMap(entries, &problem).has_value(), key, problem);
          }),
      row("imu/accel_scale", &P::imu, &Imu::accel_scale, positive<double>),
      row("imu/gyro_scale", &P::imu, &Imu::gyro_scale, positive<double>),
      row("imu/angle_scale", &P::imu, &Imu::angle_scale, positive<double>),
      row("imu/orientation_variance", &P::imu, &Imu::orientation_variance,
          [](const double& v, const std::string& key) {
            require(std::isfinite(v), key, "must be finite");
          }),
      row("imu/angular_velocity_variance", &P::imu, &Imu::angular_velocity_variance,
          nonNegative<double>),
      row("imu/linear_acceleration_variance", &P::imu, &Imu::linear_acceleration_variance,
          nonNegative<double>),

      row("servo_bus/enabled", &P::servo_bus, &Port::enabled),
      row("servo_bus/port", &P::servo_bus, &Port::port),
      row("servo_bus/baud", &P::servo_bus, &Port::baud, baudOrInherit),
      row("servo_bus/timeout", &P::servo_bus, &Bus::timeout,
          [](const double& v, const std::string& key) {
            requirePositive(v, key);
            require(v <= 5.0, key, "must be at most 5 s");
          }),
      row("servo_bus/retries", &P::servo_bus, &Bus::retries,
          [](const int& v, const std::string& key) {
            require(v >= 0 && v <= 10, key, "must be 0..10");
          }),
      row("servo_bus/allow_dangerous_writes", &P::servo_bus, &Bus::allow_dangerous_writes),
      row("servo_bus/state_ids", &P::servo_bus, &Bus::state_ids, busServoIds),
      row("servo_bus/state_rate", &P::servo_bus, &Bus::state_rate,
          [](const double& v, const std::string& key) {
            requirePositive(v, key);
            // Per servo: one servo on a fast line answers about 1000 times a second. What the
            // line cannot deliver of the asked rate is reported in diagnostics.
            require(v <= 1000, key, "must be at most 1000 Hz");
          }),
      row("servo_bus/command_interval_ms", &P::servo_bus, &Bus::command_interval_ms,
          [](const int& v, const std::string& key) {
            require(v >= 0 && v <= 65535, key, "must be 0..65535 ms");
          }),
      // Trajectory defaults (follow_joint_trajectory, joint_trajectory).
      row("trajectory/goal_tolerance", &P::trajectory, &TrajectoryParams::goal_tolerance,
          nonNegative<double>),
      row("trajectory/goal_time_tolerance", &P::trajectory, &TrajectoryParams::goal_time_tolerance,
          nonNegative<double>),
      row("trajectory/path_tolerance", &P::trajectory, &TrajectoryParams::path_tolerance,
          nonNegative<double>),
      row("trajectory/max_velocity", &P::trajectory, &TrajectoryParams::max_velocity,
          nonNegative<double>),
      // Bus servos as named joints; lengths and names are checked in validate().
      row("servo_bus/joint_ids", &P::servo_bus, &Bus::joint_ids, busServoIds),
      row("servo_bus/joint_names", &P::servo_bus, &Bus::joint_names,
          [](const std::vector<std::string>& names, const std::string& key) {
            std::set<std::string> seen;
            for (const std::string& name : names) {
              require(!name.empty(), key, "a joint name is empty");
              require(seen.insert(name).second, key, "joint '" + name + "' is listed twice");
            }
          }),
      row("servo_bus/joint_zero_deg", &P::servo_bus, &Bus::joint_zero_deg,
          [](const std::vector<double>& zeros, const std::string& key) {
            for (double zero : zeros) {
              require(std::isfinite(zero) && zero >= -180.0 && zero <= 180.0, key,
                      "must be servo angles within -180..180 deg");
            }
          }),
      row("servo_bus/joint_directions", &P::servo_bus, &Bus::joint_directions,
          [](const std::vector<int>& directions, const std::string& key) {
            for (int d : directions) require(d == 1 || d == -1, key, "entries must be 1 or -1");
          }),
      // Safe motion.
      row("servo_bus/relax_power_mw", &P::servo_bus, &Bus::relax_power_mw,
          [](const int& v, const std::string& key) {
            require(v >= 0 && v <= 65535, key, "must be 0..65535 mW");
          }),
      row("servo_bus/on_shutdown", &P::servo_bus, &Bus::on_shutdown,
          [](const std::string& v, const std::string& key) {
            require(device::shutdownActionFromString(v).has_value(), key,
                    "must be stop, relax or none, got '" + v + "'");
          }),
      row("servo_bus/health_rate", &P::servo_bus, &Bus::health_rate,
          [](const double& v, const std::string& key) {
            require(std::isfinite(v) && v >= 0.0 && v <= 10.0, key, "must be 0..10 Hz (0: off)");
          }),
      row("servo_bus/protect", &P::servo_bus, &Bus::protect),
  };
}

/// How a parameter's expected type reads in an error message.
std::string typeName(const ParamValue& value) {
  static const char* const kNames[] = {"true or false", "an integer",          "a number",
                                       "a string",      "a list of integers", "a list of strings",
                                       "a list of numbers"};
  return kNames[value.index()];
}

/// The parameter server under the node's private namespace.
class NodeHandleSource : public ParamSource {
 public:
  explicit NodeHandleSource(const ros::NodeHandle& nh) : nh_(nh) {}

  bool has(const std::string& key) const override { return nh_.hasParam(key); }

  bool get(const std::string& key, ParamValue* value) const override {
    return std::visit([&](auto& typed) { return nh_.getParam(key, typed); }, *value);
  }

  std::vector<std::string> keys() const override {
    std::vector<std::string> all;
    ros::param::getParamNames(all);
    const std::string prefix = nh_.getNamespace() + "/";
    std::vector<std::string> under;
    for (const auto& full : all) {
      if (full.compare(0, prefix.size(), prefix) == 0) under.push_back(full.substr(prefix.size()));
    }
    return under;
  }

 private:
  const ros::NodeHandle& nh_;
};

}  // namespace

std::optional<AxisMap> parseAxisMap(const std::vector<std::string>& entries, std::string* problem) {
  const auto fail = [problem](const std::string& text) {
    if (problem) *problem = text;
    return std::nullopt;
  };
  if (entries.size() != 3) {
    return fail("must list 3 axes (imu x, y, z), e.g. [x, y, z] or [-y, x, z]; got " +
                std::to_string(entries.size()));
  }
  AxisMap map;
  std::array<bool, 3> used{};
  for (std::size_t i = 0; i < 3; ++i) {
    std::string entry = entries[i];
    int sign = 1;
    if (!entry.empty() && (entry[0] == '-' || entry[0] == '+')) {
      sign = entry[0] == '-' ? -1 : 1;
      entry.erase(0, 1);
    }
    if (entry != "x" && entry != "y" && entry != "z") {
      return fail("entry '" + entries[i] + "' is not x, y or z with an optional sign");
    }
    const int source = entry[0] - 'x';
    if (used[source]) return fail("sensor axis " + entry + " is used twice");
    used[source] = true;
    map.source[i] = source;
    map.sign[i] = sign;
  }
  // The determinant of a signed permutation: the permutation's parity times the signs.
  const int inversions = (map.source[0] > map.source[1]) + (map.source[0] > map.source[2]) +
                         (map.source[1] > map.source[2]);
  const int determinant = (inversions % 2 ? -1 : 1) * map.sign[0] * map.sign[1] * map.sign[2];
  if (determinant != 1) {
    return fail("is a mirror image (left-handed); flip the sign of one axis to make it a rotation");
  }
  return map;
}

std::string resolveFrame(const std::string& tf_prefix, const std::string& frame) {
  if (!frame.empty() && frame[0] == '/') return frame.substr(1);
  const std::size_t first = tf_prefix.find_first_not_of('/');
  if (first == std::string::npos) return frame;  // empty, or nothing but slashes
  const std::size_t last = tf_prefix.find_last_not_of('/');
  return tf_prefix.substr(first, last - first + 1) + "/" + frame;
}

void DriverParams::resolveFrames() {
  base.odom_frame = resolveFrame(tf_prefix, base.odom_frame);
  base.base_frame = resolveFrame(tf_prefix, base.base_frame);
  imu.frame_id = resolveFrame(tf_prefix, imu.frame_id);
}

const std::vector<ParamSpec>& parameterTable() {
  static const std::vector<ParamSpec> table = buildTable();
  return table;
}

void DriverParams::validate() const {
  // Single values first (the table), then what relates several parameters.
  for (const auto& spec : parameterTable()) spec.check(*this);

  require(tf_prefix.find(' ') == std::string::npos, "tf_prefix", "must not contain spaces");
  require(!capture || replay_bag.empty(), "capture",
          "cannot be combined with ~replay_bag: a replay reads a capture and writes nothing");
  std::string all_devices;
  bool any_enabled = false;
  for (const device::DeviceDescription& device : device::deviceSet()) {
    all_devices += (all_devices.empty() ? "" : ", ") + std::string(device.name);
    any_enabled |= enabled(device.kind);
  }
  require(any_enabled, std::string(device::deviceSet().front().name) + "/enabled",
          "every device is disabled (" + all_devices + "): nothing to drive");
  if (base.enabled) {
    // Every tick's wheel frame is the base's heartbeat; it stops with a timeout error after 1 s
    // without one. 5 Hz leaves five frames in that second, so one lost frame is harmless.
    std::ostringstream rate;
    rate << "must be at least " << kMinBaseLoopRate
         << " Hz while the base is enabled: each loop tick sends the wheel frame that keeps the "
            "base's 1 s heartbeat alive (got "
         << loop_rate << ")";
    require(loop_rate >= kMinBaseLoopRate, "loop_rate", rate.str());
    require(base.battery_poll_rate <= loop_rate, "base/battery_poll_rate",
            "must not exceed loop_rate (requests go out from the loop)");
    require(base.battery_error_percent <= base.battery_warn_percent, "base/battery_error_percent",
            "must not exceed base/battery_warn_percent (" +
                std::to_string(base.battery_warn_percent) + ")");
    require(base.odom_frame != base.base_frame, "base/base_frame",
            "must differ from base/odom_frame ('" + base.odom_frame + "')");
    require(base.left_wheel_joint != base.right_wheel_joint, "base/right_wheel_joint",
            "must differ from base/left_wheel_joint ('" + base.left_wheel_joint + "')");
    if (base.use_imu_heading) {
      require(body.enabled, "base/use_imu_heading",
              "needs the servo controller board's IMU, but body/enabled is false");
      require(
          imu.orientation_variance >= 0, "base/use_imu_heading",
          "needs the IMU's orientation, but imu/orientation_variance is negative (no orientation)");
    }
  }
  if (body.enabled) {
    const std::size_t n = body.servo_ids.size();
    const auto requireOnePerServo = [n](std::size_t size, const std::string& name) {
      require(size == n, name,
              "has " + std::to_string(size) + " entries but body/servo_ids has " + std::to_string(n));
    };
    requireOnePerServo(body.joint_names.size(), "body/joint_names");
    requireOnePerServo(body.zero_ticks.size(), "body/zero_ticks");
    requireOnePerServo(body.directions.size(), "body/directions");
  }
  if (servo_bus.enabled) {
    const std::size_t n = servo_bus.joint_ids.size();
    const auto requireOnePerJoint = [n](std::size_t size, const std::string& name, bool may_be_empty) {
      require(size == n || (may_be_empty && size == 0), name,
              "has " + std::to_string(size) + " entries but servo_bus/joint_ids has " +
                  std::to_string(n));
    };
    requireOnePerJoint(servo_bus.joint_names.size(), "servo_bus/joint_names", false);
    requireOnePerJoint(servo_bus.joint_zero_deg.size(), "servo_bus/joint_zero_deg", true);
    requireOnePerJoint(servo_bus.joint_directions.size(), "servo_bus/joint_directions", true);
    for (const std::string& name : servo_bus.joint_names) {
      const bool body_has_it = body.enabled && std::find(body.joint_names.begin(),
                                                         body.joint_names.end(),
                                                         name) != body.joint_names.end();
      require(!body_has_it, "servo_bus/joint_names",
              "joint '" + name + "' is also a body joint (body/joint_names)");
    }
  }

  // Devices sharing a path share one port, so they must agree on its baud rate.
  struct Use {
    std::string name, path;
    int baud;
  };
  std::vector<Use> uses;
  for (const device::DeviceDescription& device : device::deviceSet()) {
    if (!enabled(device.kind)) continue;
    uses.push_back({device.name, portOf(device.kind), baudOf(device.kind)});
  }
  for (std::size_t i = 0; i < uses.size(); ++i) {
    for (std::size_t j = i + 1; j < uses.size(); ++j) {
      require(uses[i].path != uses[j].path || uses[i].baud == uses[j].baud, uses[j].name + "/baud",
              "differs from " + uses[i].name + "'s baud on the shared port " + uses[i].path);
    }
  }
}

const DevicePortParams& DriverParams::portParams(device::DeviceKind kind) const {
  switch (kind) {
    case device::DeviceKind::kBase:
      return base;
    case device::DeviceKind::kBody:
      return body;
    case device::DeviceKind::kServoBus:
      break;
  }
  return servo_bus;
}

std::string DriverParams::portOf(device::DeviceKind kind) const {
  const DevicePortParams& own = portParams(kind);
  return own.port.empty() ? port : own.port;
}

int DriverParams::baudOf(device::DeviceKind kind) const {
  const DevicePortParams& own = portParams(kind);
  return own.baud > 0 ? own.baud : baud;
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

DriverParams loadParams(const ros::NodeHandle& nh, std::vector<std::string>* unknown_keys) {
  DriverParams params = loadParams(NodeHandleSource(nh), unknown_keys);
  // ~tf_prefix, then tf_prefix in each enclosing namespace up to the root.
  std::string key;
  if (nh.searchParam("tf_prefix", key) && !nh.getParam(key, params.tf_prefix)) {
    throw ParameterError("tf_prefix", "must be a string (found " + key + ")");
  }
  params.resolveFrames();
  return params;
}

}  // namespace serial_robot_driver::ros_layer
