// Every parameter of driver_node, loaded once at start-up into one struct (names and defaults:
// docs/node_api.md and config/robot.yaml). validate() throws ParameterError naming the first
// bad parameter; the node prints it and exits non-zero.
#pragma once

#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "serial_robot_driver/transport/recorded_stream.h"
#include "serial_robot_driver/device/base_controller.h"
#include "serial_robot_driver/device/device_set.h"
#include "serial_robot_driver/device/servo_bus.h"

namespace ros {
class NodeHandle;
}

namespace serial_robot_driver::ros_layer {

class ParameterError : public std::runtime_error {
 public:
  ParameterError(const std::string& name, const std::string& problem)
      : std::runtime_error("parameter ~" + name + ": " + problem), name_(name) {}
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

/// Where a device talks: its own port/baud, or the node-wide ones.
struct DevicePortParams {
  bool enabled = true;
  std::string port;  ///< empty: the node-wide ~port
  int baud = 0;      ///< 0: the node-wide ~baud
};

/// The defaults of the core classes' configurations. The parameters that configure a core class
/// start from its values, so each default is written once (in the core config), never copied.
inline const device::BaseConfig kBaseDefaults{};
inline const device::ServoBusConfig kServoBusDefaults{};

struct BaseParams : DevicePortParams {
  double wheel_diameter = kBaseDefaults.geometry.wheel_diameter;
  int encoder_resolution = static_cast<int>(kBaseDefaults.geometry.encoder_resolution);
  double pid_rate = kBaseDefaults.geometry.pid_rate;
  double wheel_separation = kBaseDefaults.geometry.wheel_separation;
  double max_wheel_speed = kBaseDefaults.max_wheel_speed;
  double max_wheel_accel = kBaseDefaults.max_wheel_accel;
  double cmd_vel_timeout = kBaseDefaults.cmd_vel_timeout;
  bool speed_dithering = kBaseDefaults.speed_dithering;
  double battery_poll_rate = kBaseDefaults.battery_poll_rate;
  int battery_warn_percent = 20;   ///< below: diagnostics WARN
  int battery_error_percent = 10;  ///< below: diagnostics ERROR
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  bool publish_tf = true;
  /// 1 or -1: sign between forward motion and the wire's ticks
  int left_wheel_direction = kBaseDefaults.left_wheel_direction;
  int right_wheel_direction = kBaseDefaults.right_wheel_direction;
  std::string left_wheel_joint = "left_wheel_joint";  ///< wheel_states and robot description names
  std::string right_wheel_joint = "right_wheel_joint";
  /// odom's heading from the body's IMU while its telemetry is fresh (device::BaseConfig).
  bool use_imu_heading = kBaseDefaults.use_imu_heading;
};

struct BodyParams : DevicePortParams {
  std::vector<int> servo_ids{1, 2};
  std::vector<std::string> joint_names{"joint_1", "joint_2"};
  int ticks_per_revolution = 4096;
  std::vector<int> zero_ticks{2048, 2048};
  std::vector<int> directions{1, 1};
  /// rad/s per raw speed unit; 0: unknown, and joint_states carries no velocity.
  double velocity_scale = 0.0;
};

/// Where each axis of imu/data comes from: axis i (x, y, z) is sign[i] * the sensor's axis
/// source[i]. Written as ~imu/axis_map, e.g. ["x", "y", "z"] (as mounted) or ["-y", "x", "z"].
struct AxisMap {
  std::array<int, 3> source{0, 1, 2};
  std::array<int, 3> sign{1, 1, 1};
};

/// Parses an axis map: three entries "x", "y" or "z" with an optional sign, each sensor axis once,
/// and right-handed (a rotation, so the orientation can follow). nullopt with `problem` set when not.
std::optional<AxisMap> parseAxisMap(const std::vector<std::string>& entries, std::string* problem);

struct ImuParams {
  std::string frame_id = "imu_link";
  std::vector<std::string> axis_map{"x", "y", "z"};  ///< see AxisMap
  double accel_scale = 0.0047884;        ///< m/s^2 per LSB (16 g / 32768)
  double gyro_scale = 0.0010653;         ///< rad/s per LSB (2000 deg/s / 32768)
  double angle_scale = 0.0000958738;     ///< rad per LSB (180 deg / 32768)
  /// Diagonal variances (REP-145); a negative orientation variance would mean "no orientation".
  double orientation_variance = 0.0003;  ///< rad^2 (about 1 deg std)
  double angular_velocity_variance = 0.0001;   ///< (rad/s)^2
  double linear_acceleration_variance = 0.01;  ///< (m/s^2)^2
};

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
};

/// Defaults of follow_joint_trajectory and joint_trajectory (a goal's own tolerances override them).
struct TrajectoryParams {
  double goal_tolerance = 0.05;      ///< rad, per joint
  double goal_time_tolerance = 0.5;  ///< s after the last point's time to get within goal_tolerance
  double path_tolerance = 0.0;       ///< rad; 0: not checked
  double max_velocity = 0.0;         ///< rad/s per joint; a faster trajectory is refused; 0: no limit
};

/// The tf frame name of a frame parameter under `tf_prefix`, as robot_state_publisher resolves its
/// links: "<prefix>/<frame>" with the prefix's own leading and trailing slashes dropped
/// ("/robot1/" and "robot1" alike); a frame written with a leading '/' is taken as it is, without
/// the slash; an empty prefix leaves the frame as configured. The one place a frame name is made.
std::string resolveFrame(const std::string& tf_prefix, const std::string& frame);

/// Below this loop rate the base's 1 s heartbeat is at risk (validate() says so).
constexpr double kMinBaseLoopRate = 5.0;

struct DriverParams {
  std::string port = "/dev/ttyUSB0";
  int baud = 115200;
  double loop_rate = kBaseDefaults.loop_rate;
  double reconnect_interval = 1.0;
  bool capture = false;      ///< publish every chunk in and out on serial_raw
  std::string replay_bag;    ///< non-empty: read the ports from this bag's serial_raw, not the wire
  double replay_rate = 1.0;  ///< replay speed; 0: as fast as possible
  /// Not a parameter: the running replay's timeline (set by the node once the bag is read), which
  /// maps the frames' arrival times back to their recorded stamps.
  std::shared_ptr<const transport::ReplayPacing> replay_timeline;
  BaseParams base;
  BodyParams body;
  ImuParams imu;
  ServoBusParams servo_bus;
  /// Not a ~ parameter: `tf_prefix` searched upward from the node's namespace (as
  /// robot_state_publisher does), so one value in a robot's namespace serves all its nodes.
  std::string tf_prefix;

  /// Puts every frame parameter (base/odom_frame, base/base_frame, imu/frame_id) under tf_prefix
  /// (resolveFrame). loadParams(NodeHandle) calls it once, after reading tf_prefix.
  void resolveFrames();
  TrajectoryParams trajectory;

  /// Throws ParameterError naming the first parameter that is out of range or inconsistent.
  void validate() const;

  /// The port parameters (~<name>/enabled, port, baud) of a device of the set.
  const DevicePortParams& portParams(device::DeviceKind kind) const;
  bool enabled(device::DeviceKind kind) const { return portParams(kind).enabled; }
  /// The device's own port or baud, or the node-wide one it inherits.
  std::string portOf(device::DeviceKind kind) const;
  int baudOf(device::DeviceKind kind) const;
  std::string basePort() const { return portOf(device::DeviceKind::kBase); }
  std::string bodyPort() const { return portOf(device::DeviceKind::kBody); }
  std::string servoBusPort() const { return portOf(device::DeviceKind::kServoBus); }
  int baseBaud() const { return baudOf(device::DeviceKind::kBase); }
  int bodyBaud() const { return baudOf(device::DeviceKind::kBody); }
  int servoBusBaud() const { return baudOf(device::DeviceKind::kServoBus); }
  /// A topic's publisher queue: `live` frames (a slow subscriber drops old ones), but unbounded
  /// while replaying, where a full-speed replay must not lose what subscribers have not read yet.
  int publisherQueue(int live) const { return replay_bag.empty() ? live : 0; }
};

/// One parameter's value; the alternative held says the parameter's type.
using ParamValue =
    std::variant<bool, int, double, std::string, std::vector<int>, std::vector<std::string>,
                 std::vector<double>>;

/// One row of the parameter table: the key under ~ and how it reaches its DriverParams field.
/// The table (parameterTable()) is the only place a key is spelled: loading, the unknown-key
/// warning and the single-value range checks of validate() all walk it.
struct ParamSpec {
  std::string key;
  std::function<ParamValue(const DriverParams&)> get;
  std::function<void(DriverParams&, const ParamValue&)> set;
  /// Throws ParameterError(key, ...) when the field's value is out of range; checked only while
  /// the device the key belongs to is enabled.
  std::function<void(const DriverParams&)> check;
};

const std::vector<ParamSpec>& parameterTable();

/// Where loadParams reads from: the parameter server (loadParams below), or a map in tests.
class ParamSource {
 public:
  virtual ~ParamSource() = default;
  virtual bool has(const std::string& key) const = 0;
  /// Overwrites `value` (keeping its alternative) with the stored value of `key`; false when the
  /// stored value has another type.
  virtual bool get(const std::string& key, ParamValue* value) const = 0;
  /// Every key the source holds (relative to ~).
  virtual std::vector<std::string> keys() const = 0;
};

/// Reads every table key present in `source` (missing keys keep their defaults; a key of the
/// wrong type is a ParameterError). `unknown_keys` receives the keys the driver does not know.
DriverParams loadParams(const ParamSource& source, std::vector<std::string>* unknown_keys);

/// Reads every parameter from the private namespace of `private_nh` (missing keys keep their
/// defaults; a key of the wrong type is a ParameterError). `unknown_keys` receives the keys under ~
/// that the driver does not know (typos), for a warning.
DriverParams loadParams(const ros::NodeHandle& private_nh, std::vector<std::string>* unknown_keys);

}  // namespace serial_robot_driver::ros_layer
