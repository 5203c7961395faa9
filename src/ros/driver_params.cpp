#include "serial_robot_driver/ros/driver_params.h"

#include <cmath>
#include <set>
#include <sstream>

#include <ros/node_handle.h>
#include <ros/param.h>

#include "serial_robot_driver/protocol/body_codec.h"

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
  static const std::set<int> kRates = {1200,   2400,   4800,   9600,    19200,   38400,  57600,
                                       115200, 230400, 250000, 460800,  500000,  576000, 921600,
                                       1000000, 1500000, 2000000, 3000000, 4000000};
  if (zero_means_inherit && baud == 0) return;
  require(kRates.count(baud) > 0, name,
          "unsupported baud rate " + std::to_string(baud) + " (e.g. 9600, 115200, 1000000)");
}

void validateDevicePort(const DevicePortParams& device, const std::string& prefix) {
  requireBaud(device.baud, prefix + "/baud", true);
}

// --- loading --------------------------------------------------------------------------------

/// How a parameter's expected type reads in an error message.
std::string typeName(bool) { return "true or false"; }
std::string typeName(int) { return "an integer"; }
std::string typeName(double) { return "a number"; }
std::string typeName(const std::string&) { return "a string"; }
std::string typeName(const std::vector<int>&) { return "a list of integers"; }
std::string typeName(const std::vector<std::string>&) { return "a list of strings"; }

/// Reads keys under ~ and remembers which ones it was asked for, so what is left on the parameter
/// server afterwards is exactly the keys the driver does not know.
class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}

  /// Reads `key` when present; a present key of the wrong type is an error, not a silent default.
  template <typename T>
  void read(const std::string& key, T* value) {
    known_.insert(key);
    if (!nh_.hasParam(key)) return;
    if (!nh_.getParam(key, *value)) throw ParameterError(key, "must be " + typeName(*value));
  }

  void readDevice(const std::string& prefix, DevicePortParams* device) {
    read(prefix + "/enabled", &device->enabled);
    read(prefix + "/port", &device->port);
    read(prefix + "/baud", &device->baud);
  }

  /// Keys under ~ that no read() asked for.
  std::vector<std::string> unreadKeys() const {
    std::vector<std::string> all;
    ros::param::getParamNames(all);
    const std::string prefix = nh_.getNamespace() + "/";
    std::vector<std::string> unread;
    for (const auto& full : all) {
      if (full.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string key = full.substr(prefix.size());
      if (!known_.count(key)) unread.push_back(key);
    }
    return unread;
  }

 private:
  const ros::NodeHandle& nh_;
  std::set<std::string> known_ = {"diagnostic_period"};  // read by diagnostic_updater itself
};

}  // namespace

void DriverParams::validate() const {
  require(!port.empty(), "port", "must name a serial device, e.g. /dev/ttyUSB0");
  requireBaud(baud, "baud", false);
  requirePositive(loop_rate, "loop_rate");
  require(loop_rate <= 1000, "loop_rate", "must be at most 1000 Hz");
  requirePositive(reconnect_interval, "reconnect_interval");
  requireNonNegative(read_poll_interval, "read_poll_interval");
  require(base.enabled || body.enabled || servo_bus.enabled, "base/enabled",
          "every device is disabled (base, body, servo_bus): nothing to drive");

  if (base.enabled) {
    validateDevicePort(base, "base");
    requirePositive(base.wheel_diameter, "base/wheel_diameter");
    requirePositive(base.encoder_resolution, "base/encoder_resolution");
    requirePositive(base.pid_rate, "base/pid_rate");
    requirePositive(base.wheel_separation, "base/wheel_separation");
    requireNonNegative(base.max_wheel_speed, "base/max_wheel_speed");
    requireNonNegative(base.max_wheel_accel, "base/max_wheel_accel");
    requirePositive(base.cmd_vel_timeout, "base/cmd_vel_timeout");
    requireNonNegative(base.battery_poll_rate, "base/battery_poll_rate");
    require(base.battery_poll_rate <= loop_rate, "base/battery_poll_rate",
            "must not exceed loop_rate (requests go out from the loop)");
  }

  if (body.enabled) {
    validateDevicePort(body, "body");
    const std::size_t n = body.servo_ids.size();
    require(n > 0, "body/servo_ids", "must list at least one servo id");
    require(n <= protocol::body::kMaxTelemetryServos, "body/servo_ids",
            "at most " + std::to_string(protocol::body::kMaxTelemetryServos) +
                " servos fit in a telemetry frame");
    std::set<int> seen;
    for (int id : body.servo_ids) {
      require(id >= 0 && id <= 253, "body/servo_ids",
              "ids must be 0..253 (254 is broadcast), got " + std::to_string(id));
      require(seen.insert(id).second, "body/servo_ids", "id " + std::to_string(id) + " is listed twice");
    }
    require(body.joint_names.size() == n, "body/joint_names",
            "has " + std::to_string(body.joint_names.size()) + " entries but body/servo_ids has " +
                std::to_string(n));
    std::set<std::string> names;
    for (const auto& name : body.joint_names) {
      require(!name.empty(), "body/joint_names", "a joint name is empty");
      require(names.insert(name).second, "body/joint_names", "'" + name + "' is listed twice");
    }
    require(body.ticks_per_revolution > 0, "body/ticks_per_revolution", "must be > 0");
    require(body.zero_ticks.size() == n, "body/zero_ticks",
            "has " + std::to_string(body.zero_ticks.size()) + " entries but body/servo_ids has " +
                std::to_string(n));
    for (int zero : body.zero_ticks) {
      require(zero >= 0 && zero <= 65535, "body/zero_ticks", "entries must be 0..65535");
    }
    require(body.directions.size() == n, "body/directions",
            "has " + std::to_string(body.directions.size()) + " entries but body/servo_ids has " +
                std::to_string(n));
    for (int direction : body.directions) {
      require(direction == 1 || direction == -1, "body/directions", "entries must be 1 or -1");
    }
    requireNonNegative(body.velocity_scale, "body/velocity_scale");
    require(!imu.frame_id.empty(), "imu/frame_id", "must not be empty");
    requirePositive(imu.accel_scale, "imu/accel_scale");
    requirePositive(imu.gyro_scale, "imu/gyro_scale");
    requirePositive(imu.angle_scale, "imu/angle_scale");
    require(std::isfinite(imu.orientation_variance), "imu/orientation_variance", "must be finite");
    requireNonNegative(imu.angular_velocity_variance, "imu/angular_velocity_variance");
    requireNonNegative(imu.linear_acceleration_variance, "imu/linear_acceleration_variance");
  }

  if (servo_bus.enabled) {
    validateDevicePort(servo_bus, "servo_bus");
    requirePositive(servo_bus.timeout, "servo_bus/timeout");
    require(servo_bus.timeout <= 5.0, "servo_bus/timeout", "must be at most 5 s");
    require(servo_bus.retries >= 0 && servo_bus.retries <= 10, "servo_bus/retries", "must be 0..10");
  }

  // Devices sharing a path share one port, so they must agree on its baud rate.
  struct Use {
    std::string name, path;
    int baud;
  };
  std::vector<Use> uses;
  if (base.enabled) uses.push_back({"base", basePort(), baseBaud()});
  if (body.enabled) uses.push_back({"body", bodyPort(), bodyBaud()});
  if (servo_bus.enabled) uses.push_back({"servo_bus", servoBusPort(), servoBusBaud()});
  for (std::size_t i = 0; i < uses.size(); ++i) {
    for (std::size_t j = i + 1; j < uses.size(); ++j) {
      require(uses[i].path != uses[j].path || uses[i].baud == uses[j].baud, uses[j].name + "/baud",
              "differs from " + uses[i].name + "'s baud on the shared port " + uses[i].path);
    }
  }
}

DriverParams loadParams(const ros::NodeHandle& nh, std::vector<std::string>* unknown_keys) {
  DriverParams p;
  ParamReader reader(nh);
  reader.read("port", &p.port);
  reader.read("baud", &p.baud);
  reader.read("loop_rate", &p.loop_rate);
  reader.read("reconnect_interval", &p.reconnect_interval);
  reader.read("read_poll_interval", &p.read_poll_interval);

  reader.readDevice("base", &p.base);
  reader.read("base/wheel_diameter", &p.base.wheel_diameter);
  reader.read("base/encoder_resolution", &p.base.encoder_resolution);
  reader.read("base/pid_rate", &p.base.pid_rate);
  reader.read("base/wheel_separation", &p.base.wheel_separation);
  reader.read("base/max_wheel_speed", &p.base.max_wheel_speed);
  reader.read("base/max_wheel_accel", &p.base.max_wheel_accel);
  reader.read("base/cmd_vel_timeout", &p.base.cmd_vel_timeout);
  reader.read("base/speed_dithering", &p.base.speed_dithering);
  reader.read("base/battery_poll_rate", &p.base.battery_poll_rate);

  reader.readDevice("body", &p.body);
  reader.read("body/servo_ids", &p.body.servo_ids);
  reader.read("body/joint_names", &p.body.joint_names);
  reader.read("body/ticks_per_revolution", &p.body.ticks_per_revolution);
  reader.read("body/zero_ticks", &p.body.zero_ticks);
  reader.read("body/directions", &p.body.directions);
  reader.read("body/velocity_scale", &p.body.velocity_scale);

  reader.read("imu/frame_id", &p.imu.frame_id);
  reader.read("imu/accel_scale", &p.imu.accel_scale);
  reader.read("imu/gyro_scale", &p.imu.gyro_scale);
  reader.read("imu/angle_scale", &p.imu.angle_scale);
  reader.read("imu/orientation_variance", &p.imu.orientation_variance);
  reader.read("imu/angular_velocity_variance", &p.imu.angular_velocity_variance);
  reader.read("imu/linear_acceleration_variance", &p.imu.linear_acceleration_variance);

  reader.readDevice("servo_bus", &p.servo_bus);
  reader.read("servo_bus/timeout", &p.servo_bus.timeout);
  reader.read("servo_bus/retries", &p.servo_bus.retries);
  reader.read("servo_bus/allow_dangerous_writes", &p.servo_bus.allow_dangerous_writes);

  if (unknown_keys) *unknown_keys = reader.unreadKeys();
  return p;
}

}  // namespace serial_robot_driver::ros_layer
