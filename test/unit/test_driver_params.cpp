// DriverParams::validate(): defaults are valid, and every kind of bad value is reported with the
// name of the parameter at fault.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/transport/serial_port.h"

namespace serial_robot_driver::ros_layer {
namespace {

using devices::base::kMinBaseLoopRate;
using devices::body::AxisMap;
using devices::body::parseAxisMap;

TEST(DriverParams, DefaultsAreValid) { EXPECT_NO_THROW(DriverParams().validate()); }

struct BadCase {
  const char* expected_name;
  std::function<void(DriverParams&)> spoil;
};

class DriverParamsBad : public ::testing::TestWithParam<BadCase> {};

TEST_P(DriverParamsBad, NamesTheParameter) {
  DriverParams params;
  try {
    // A converted row refuses a bad value already when it is set (its check sees it as written).
    GetParam().spoil(params);
    params.validate();
    FAIL() << "no error for " << GetParam().expected_name;
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), GetParam().expected_name) << e.what();
    EXPECT_NE(std::string(e.what()).find(GetParam().expected_name), std::string::npos);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, DriverParamsBad,
    ::testing::Values(
        BadCase{"port", [](DriverParams& p) { p.port.clear(); }},
        BadCase{"baud", [](DriverParams& p) { p.baud = 12345; }},
        BadCase{"loop_rate", [](DriverParams& p) { p.loop_rate = 0; }},
        BadCase{"reconnect_interval", [](DriverParams& p) { p.reconnect_interval = -1; }},
        BadCase{"realtime_priority", [](DriverParams& p) { p.realtime_priority = -1; }},
        BadCase{"realtime_priority", [](DriverParams& p) { p.realtime_priority = 100; }},
        BadCase{"scheduler_slice_us", [](DriverParams& p) { p.scheduler_slice_us = -1; }},
        BadCase{"scheduler_slice_us", [](DriverParams& p) { p.scheduler_slice_us = 99; }},
        BadCase{"scheduler_slice_us", [](DriverParams& p) { p.scheduler_slice_us = 100001; }},
        BadCase{"scheduler_slice_us",
                [](DriverParams& p) { p.scheduler_slice_us = std::numeric_limits<int>::min(); }},
        BadCase{"replay_rate", [](DriverParams& p) { p.replay_rate = -1; }},
        BadCase{"capture",
                [](DriverParams& p) {
                  p.capture = true;
                  p.replay_bag = "/tmp/field.bag";
                }},
        BadCase{"base/wheel_diameter",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.geometry.wheel_diameter = -0.25; }},
        BadCase{"base/wheel_diameter",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.geometry.wheel_diameter = std::nan(""); }},
        BadCase{"base/encoder_resolution",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.geometry.encoder_resolution = 0; }},
        BadCase{"base/pid_rate", [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.geometry.pid_rate = 0; }},
        BadCase{"base/wheel_separation",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.geometry.wheel_separation = 0; }},
        BadCase{"base/max_wheel_speed",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.max_wheel_speed = -1; }},
        // 0 is no "no limit": the speed limit cannot be switched off.
        BadCase{"base/max_wheel_speed",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.max_wheel_speed = 0; }},
        BadCase{"base/max_wheel_speed",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.max_wheel_speed = std::nan(""); }},
        BadCase{"base/max_wheel_accel",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.max_wheel_accel = -1; }},
        BadCase{"base/cmd_vel_timeout",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.cmd_vel_timeout = 0; }},
        // Bounded: the deadman that stops the base when cmd_vel stops cannot be tuned away.
        BadCase{"base/cmd_vel_timeout",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.cmd_vel_timeout = 5.01; }},
        BadCase{"base/battery_poll_rate",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.battery_poll_rate = -1; }},
        BadCase{"base/baud", [](DriverParams& p) { p.section(devices::base::kBaseSection).baud = 7; }},
        BadCase{"loop_rate", [](DriverParams& p) { p.loop_rate = 1.0; }},  // heartbeat at risk
        BadCase{"loop_rate", [](DriverParams& p) { p.loop_rate = 4.9; }},
        BadCase{"base/battery_warn_percent",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).battery_warn_percent = 101; }},
        BadCase{"base/battery_error_percent",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).battery_error_percent = -1; }},
        BadCase{"base/battery_error_percent",
                [](DriverParams& p) {
                  p.section(devices::base::kBaseSection).battery_warn_percent = 10;
                  p.section(devices::base::kBaseSection).battery_error_percent = 20;
                }},
        BadCase{"base/odom_frame", [](DriverParams& p) { p.section(devices::base::kBaseSection).odom_frame.clear(); }},
        BadCase{"base/base_frame", [](DriverParams& p) { p.section(devices::base::kBaseSection).base_frame = "base link"; }},
        BadCase{"base/base_frame", [](DriverParams& p) { p.section(devices::base::kBaseSection).base_frame = "odom"; }},
        BadCase{"base/left_wheel_direction",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.left_wheel_direction = 0; }},
        BadCase{"base/right_wheel_direction",
                [](DriverParams& p) { p.section(devices::base::kBaseSection).controller.right_wheel_direction = 2; }},
        BadCase{"body/servo_ids", [](DriverParams& p) { p.section(devices::body::kBodySection).servo_ids = {}; }},
        BadCase{"body/servo_ids", [](DriverParams& p) { p.section(devices::body::kBodySection).servo_ids = {1, 1}; }},
        BadCase{"body/servo_ids", [](DriverParams& p) { p.section(devices::body::kBodySection).servo_ids = {1, 300}; }},
        BadCase{"body/joint_names", [](DriverParams& p) { p.section(devices::body::kBodySection).joint_names = {"a"}; }},
        BadCase{"body/joint_names", [](DriverParams& p) { p.section(devices::body::kBodySection).joint_names = {"a", "a"}; }},
        BadCase{"body/zero_ticks", [](DriverParams& p) { p.section(devices::body::kBodySection).zero_ticks = {0}; }},
        BadCase{"body/zero_ticks", [](DriverParams& p) { p.section(devices::body::kBodySection).zero_ticks = {0, 70000}; }},
        BadCase{"body/directions", [](DriverParams& p) { p.section(devices::body::kBodySection).directions = {1, 2}; }},
        BadCase{"body/ticks_per_revolution",
                [](DriverParams& p) { p.section(devices::body::kBodySection).calibration.ticks_per_revolution = 0; }},
        BadCase{"body/velocity_scale",
                [](DriverParams& p) { p.section(devices::body::kBodySection).calibration.velocity_scale = -1; }},
        BadCase{"imu/frame_id", [](DriverParams& p) { p.section(devices::body::kImuSection).frame_id.clear(); }},
        BadCase{"imu/accel_scale", [](DriverParams& p) { p.section(devices::body::kImuSection).accel_scale = 0; }},
        BadCase{"imu/axis_map", [](DriverParams& p) { p.section(devices::body::kImuSection).axis_map = {"x", "y"}; }},
        BadCase{"imu/axis_map", [](DriverParams& p) { p.section(devices::body::kImuSection).axis_map = {"x", "x", "z"}; }},
        BadCase{"imu/axis_map", [](DriverParams& p) { p.section(devices::body::kImuSection).axis_map = {"x", "y", "w"}; }},
        BadCase{"imu/axis_map", [](DriverParams& p) { p.section(devices::body::kImuSection).axis_map = {"x", "y", "-z"}; }},
        BadCase{"imu/axis_map", [](DriverParams& p) { p.section(devices::body::kImuSection).axis_map = {"y", "x", "z"}; }},
        BadCase{
            "servo_bus/timeout",
            [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).bus.client.timeout = std::chrono::milliseconds(0); }},
        BadCase{"servo_bus/timeout",
                [](DriverParams& p) { params::specFor("servo_bus/timeout").set(p, -0.0004); }},
        BadCase{"servo_bus/retries", [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).bus.client.retries = -1; }},
        BadCase{"servo_bus/baud", [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).baud = 9600; }},
        // 253 puts FF FF FD (the sync-write header) inside a sync-write frame.
        BadCase{"body/servo_ids", [](DriverParams& p) { p.section(devices::body::kBodySection).servo_ids = {1, 253}; }},
        BadCase{"servo_bus/state_ids", [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).state_ids = {1, 255}; }},
        BadCase{"servo_bus/state_ids", [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).state_ids = {4, 4}; }},
        BadCase{"servo_bus/state_rate", [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).bus.poll_rate = 0; }},
        BadCase{"servo_bus/state_rate", [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).bus.poll_rate = 1001; }},
        BadCase{"servo_bus/command_interval_ms",
                [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).command_interval_ms = 70000; }},
        BadCase{
            "servo_bus/on_shutdown",
            [](DriverParams&
                   p) { params::specFor("servo_bus/on_shutdown").set(p, std::string("halt")); }},
        BadCase{"servo_bus/relax_power_mw",
                [](DriverParams& p) { params::specFor("servo_bus/relax_power_mw").set(p, -1); }},
        BadCase{"servo_bus/health_rate",
                [](DriverParams& p) { p.section(devices::servo_bus::kServoBusSection).bus.health_rate = -1.0; }},
        BadCase{"ros2/domain_id", [](DriverParams& p) { p.ros2.domain_id = 233; }},
        BadCase{"ros2/domain_id", [](DriverParams& p) { p.ros2.domain_id = -2; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {"10.0.0.256"}; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {"10.0.1"}; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {"robot 2"}; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {"-robot"}; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {""}; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {"robot..lan"}; }},
        BadCase{"ros2/peers", [](DriverParams& p) { p.ros2.peers = {"127.0.0.1", "127.0.0.1"}; }},
        BadCase{"base/enabled", [](DriverParams& p) {
                  p.section(devices::base::kBaseSection).enabled = p.section(devices::body::kBodySection).enabled = p.section(devices::servo_bus::kServoBusSection).enabled = false;
                }}));

TEST(DriverParams, Ros2DomainsAndPeersAtTheirLimitsPass) {
  DriverParams params;
  params.ros2.peers = {"127.0.0.1", "255.255.255.255", "robot-2.local", "base7"};
  for (const int domain : {-1, 0, 232}) {
    params.ros2.domain_id = domain;
    EXPECT_NO_THROW(params.validate()) << domain;
  }
}

TEST(DriverParams, ImuHeadingNeedsTheBodysImuOrientation) {
  DriverParams params;
  params.section(devices::base::kBaseSection).controller.use_imu_heading = true;
  EXPECT_NO_THROW(params.validate());
  const auto expectRefused = [](const DriverParams& p, const std::string& reason) {
    try {
      p.validate();
      FAIL() << "no error for " << reason;
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.name(), "base/use_imu_heading");
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  DriverParams no_body = params;
  no_body.section(devices::body::kBodySection).enabled = false;
  expectRefused(no_body, "body/enabled is false");
  DriverParams no_orientation = params;
  no_orientation.section(devices::body::kImuSection).orientation_variance = -1;
  expectRefused(no_orientation, "imu/orientation_variance is negative");
}

// Every rate the port opens at passes the check, and only those: the servos' 250000 and the large
// standard rates included (one table decides both).
TEST(DriverParams, EveryRateThePortOpensAtPasses) {
  for (unsigned rate : transport::supportedBaudRates()) {
    DriverParams params;
    params.baud = static_cast<int>(rate);
    EXPECT_NO_THROW(params.validate()) << rate;
  }
  for (int rate : {9600, 19200, 38400, 57600, 115200, 250000, 500000, 1152000, 2500000, 3500000}) {
    DriverParams params;
    params.section(devices::servo_bus::kServoBusSection).port = "/dev/ttyUSB1";
    params.section(devices::servo_bus::kServoBusSection).baud = rate;
    EXPECT_NO_THROW(params.validate()) << rate;
  }
  DriverParams params;
  params.baud = 5000000;
  EXPECT_THROW(params.validate(), ParameterError);
}

// A port may be a network serial server's tcp://HOST:PORT; one that does not parse is refused at
// start-up, naming the parameter and what is wrong.
TEST(DriverParams, TcpPortsAreCheckedAtStartUp) {
  DriverParams params;
  params.port = "tcp://127.0.0.1:4001";
  params.section(devices::servo_bus::kServoBusSection).port = "tcp://[::1]:4002";
  EXPECT_NO_THROW(params.validate());

  params.section(devices::base::kBaseSection).port = "tcp://host:99999";
  try {
    params.validate();
    FAIL() << "port 99999 accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "base/port");
    EXPECT_NE(std::string(e.what()).find("tcp://host:99999: port must be 1-65535"),
              std::string::npos)
        << e.what();
  }
  params.section(devices::base::kBaseSection).port.clear();
  params.port = "tcp://" + std::string(100000, 'x');
  try {
    params.validate();
    FAIL() << "a URL without a port accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "port");
    EXPECT_LT(std::string(e.what()).size(), 300u) << "a hostile value must not flood the log";
  }
}

TEST(DriverParams, DevicesOnSeparatePortsMayUseDifferentBauds) {
  DriverParams params;
  params.section(devices::servo_bus::kServoBusSection).port = "/dev/ttyUSB1";
  params.section(devices::servo_bus::kServoBusSection).baud = 9600;
  EXPECT_NO_THROW(params.validate());
  const core::DeviceModule& bus = *core::findDevice("servo_bus");
  const core::DeviceModule& base = *core::findDevice("base");
  EXPECT_EQ(params.portOf(bus), "/dev/ttyUSB1");
  EXPECT_EQ(params.baudOf(bus), 9600);
  EXPECT_EQ(params.portOf(base), "/dev/ttyUSB0");
  EXPECT_EQ(params.baudOf(base), 115200);
}

TEST(DriverParams, DisabledDeviceIsNotValidated) {
  DriverParams params;
  params.section(devices::body::kBodySection).enabled = false;
  params.section(devices::body::kBodySection).joint_names = {};
  EXPECT_NO_THROW(params.validate());
}

TEST(DriverParams, SlowLoopRateIsRefusedWithTheReason) {
  DriverParams params;
  params.loop_rate = 1.0;
  try {
    params.validate();
    FAIL() << "1 Hz accepted: the base would sit in its 1 s timeout";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("heartbeat"), std::string::npos) << e.what();
  }
  params.section(devices::base::kBaseSection).enabled = false;  // only the base needs the heartbeat
  EXPECT_NO_THROW(params.validate());
  params.section(devices::base::kBaseSection).enabled = true;
  params.loop_rate = kMinBaseLoopRate;
  EXPECT_NO_THROW(params.validate());
}

TEST(DriverParams, SchedulerSliceTakesOffAndTheKernelsWholeRange) {
  DriverParams params;
  EXPECT_EQ(params.scheduler_slice_us, 100) << "on by default, at the kernel's least";
  for (int slice_us : {0, 100, 1000, 100000}) {
    params.scheduler_slice_us = slice_us;
    EXPECT_NO_THROW(params.validate()) << slice_us;
  }
}

TEST(DriverParams, RealtimePriorityTakesOffAndEverySchedFifoPriority) {
  DriverParams params;
  for (int priority : {0, 1, 50, 99}) {
    params.realtime_priority = priority;
    EXPECT_NO_THROW(params.validate()) << priority;
  }
}

/// A parameter server stand-in: keys relative to ~ and their values.
class MapSource : public ParamSource {
 public:
  std::map<std::string, ParamValue> values;

  bool has(const std::string& key) const override { return values.count(key) > 0; }
  bool get(const std::string& key, ParamValue* value) const override {
    const ParamValue& stored = values.at(key);
    if (stored.index() != value->index()) return false;
    *value = stored;
    return true;
  }
  std::vector<std::string> keys() const override {
    std::vector<std::string> all;
    for (const auto& entry : values) all.push_back(entry.first);
    return all;
  }
};

/// A value of the same type as `value` that differs from it.
ParamValue changed(const ParamValue& value) {
  struct Change {
    ParamValue operator()(bool v) const { return !v; }
    ParamValue operator()(int v) const { return v + 7; }
    ParamValue operator()(double v) const { return v + 0.5; }
    ParamValue operator()(const std::string& v) const { return v + "_changed"; }
    ParamValue operator()(std::vector<int> v) const {
      v.push_back(99);
      return v;
    }
    ParamValue operator()(std::vector<std::string> v) const {
      v.push_back("changed");
      return v;
    }
    ParamValue operator()(std::vector<double> v) const {
      v.push_back(0.25);
      return v;
    }
  };
  return std::visit(Change{}, value);
}

TEST(AxisMap, RotationsParseAndMirrorsAreRefusedWithAReason) {
  const std::optional<AxisMap> turned = parseAxisMap({"-y", "x", "z"}, nullptr);
  ASSERT_TRUE(turned.has_value());
  EXPECT_EQ(turned->source, (std::array<int, 3>{1, 0, 2}));
  EXPECT_EQ(turned->sign, (std::array<int, 3>{-1, 1, 1}));
  EXPECT_TRUE(parseAxisMap({"x", "-y", "-z"}, nullptr).has_value());  // upside down
  EXPECT_TRUE(parseAxisMap({"+z", "x", "y"}, nullptr).has_value());   // cyclic: a rotation
  std::string problem;
  EXPECT_FALSE(parseAxisMap({"y", "x", "z"}, &problem).has_value());
  EXPECT_NE(problem.find("left-handed"), std::string::npos) << problem;
  EXPECT_FALSE(parseAxisMap({"x", "y", "y"}, &problem).has_value());
  EXPECT_NE(problem.find("used twice"), std::string::npos) << problem;
}

TEST(ParameterTable, KeysAreUnique) {
  std::set<std::string> keys;
  for (const auto& spec : parameterTable()) EXPECT_TRUE(keys.insert(spec.key).second) << spec.key;
  EXPECT_EQ(keys.size(), parameterTable().size());
}

TEST(ParameterTable, NothingGivenLoadsTheStructDefaults) {
  const DriverParams defaults;
  std::vector<std::string> unknown{"stale"};
  const DriverParams loaded = loadParams(MapSource(), &unknown);
  EXPECT_TRUE(unknown.empty());
  for (const auto& spec : parameterTable()) {
    EXPECT_TRUE(spec.get(loaded) == spec.get(defaults)) << spec.key;
  }
  EXPECT_EQ(loaded.section(devices::base::kBaseSection).controller.geometry.wheel_diameter, 0.25);
  EXPECT_EQ(loaded.section(devices::servo_bus::kServoBusSection).bus.client.retries, 1);
}

TEST(ParameterTable, EachKeyLoadsIntoItsOwnField) {
  const DriverParams defaults;
  for (const auto& spec : parameterTable()) {
    MapSource source;
    // An enumerated value changes to another choice (its row refuses a made-up one).
    source.values[spec.key] = spec.key == "servo_bus/on_shutdown" ? ParamValue(std::string("relax"))
                                                                  : changed(spec.get(defaults));
    std::vector<std::string> unknown;
    const DriverParams loaded = loadParams(source, &unknown);
    EXPECT_TRUE(unknown.empty()) << spec.key;
    EXPECT_TRUE(spec.get(loaded) == source.values[spec.key]) << spec.key << " did not load";
    for (const auto& other : parameterTable()) {
      if (other.key == spec.key) continue;
      EXPECT_TRUE(other.get(loaded) == other.get(defaults))
          << "loading " << spec.key << " changed " << other.key;
    }
  }
}

TEST(ParameterTable, KnownKeysByNameAndType) {
  MapSource source;
  source.values["base/wheel_diameter"] = 0.3;
  source.values["body/servo_ids"] = std::vector<int>{4, 5, 6};
  source.values["servo_bus/allow_dangerous_writes"] = true;
  source.values["port"] = std::string("/dev/ttyACM0");
  source.values["diagnostic_period"] = 2.0;
  source.values["base/wheel_diamter"] = 0.3;
  std::vector<std::string> unknown;
  const DriverParams loaded = loadParams(source, &unknown);
  EXPECT_EQ(loaded.section(devices::base::kBaseSection).controller.geometry.wheel_diameter, 0.3);
  EXPECT_EQ(loaded.section(devices::body::kBodySection).servo_ids, (std::vector<int>{4, 5, 6}));
  EXPECT_TRUE(
      loaded.section(devices::servo_bus::kServoBusSection).bus.client.allow_dangerous_writes);
  EXPECT_EQ(loaded.port, "/dev/ttyACM0");
  EXPECT_EQ(unknown, std::vector<std::string>{"base/wheel_diamter"});
}

TEST(ParameterTable, WrongTypeNamesTheParameter) {
  MapSource source;
  source.values["base/encoder_resolution"] = 1600.5;
  try {
    loadParams(source, nullptr);
    FAIL() << "a number accepted for an integer parameter";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "base/encoder_resolution");
    EXPECT_NE(std::string(e.what()).find("an integer"), std::string::npos) << e.what();
  }
}

// --- tf_prefix ---------------------------------------------------------------------------------

TEST(ResolveFrame, PrefixGoesInFrontWithOneSlash) {
  EXPECT_EQ(resolveFrame("robot1", "odom"), "robot1/odom");
  EXPECT_EQ(resolveFrame("robot1", "base_link"), "robot1/base_link");
}

TEST(ResolveFrame, EmptyPrefixLeavesTheFrameAsConfigured) {
  EXPECT_EQ(resolveFrame("", "odom"), "odom");
  EXPECT_EQ(resolveFrame("", "some/frame"), "some/frame");
  EXPECT_EQ(resolveFrame("/", "odom"), "odom") << "a prefix of slashes only is no prefix";
}

TEST(ResolveFrame, LeadingSlashFrameIsTakenAsItIsWithoutTheSlash) {
  EXPECT_EQ(resolveFrame("robot1", "/map"), "map");
  EXPECT_EQ(resolveFrame("", "/odom"), "odom");
  EXPECT_EQ(resolveFrame("robot1", "/shared/odom"), "shared/odom");
}

TEST(ResolveFrame, PrefixSlashesAreTrimmedInnerOnesKept) {
  EXPECT_EQ(resolveFrame("/robot1", "odom"), "robot1/odom");
  EXPECT_EQ(resolveFrame("robot1/", "odom"), "robot1/odom");
  EXPECT_EQ(resolveFrame("//robot1//", "odom"), "robot1/odom");
  EXPECT_EQ(resolveFrame("fleet/robot1", "imu_link"), "fleet/robot1/imu_link");
}

TEST(DriverParamsFrames, ResolveFramesPrefixesEveryFrameParameter) {
  DriverParams params;
  params.tf_prefix = "robot2";
  params.section(devices::body::kImuSection).frame_id = "/imu_shared";
  params.resolveFrames();
  EXPECT_EQ(params.section(devices::base::kBaseSection).odom_frame, "robot2/odom");
  EXPECT_EQ(params.section(devices::base::kBaseSection).base_frame, "robot2/base_link");
  EXPECT_EQ(params.section(devices::body::kImuSection).frame_id, "imu_shared");
  EXPECT_NO_THROW(params.validate());
}

TEST(DriverParamsFrames, BadPrefixOrFrameIsNamed) {
  DriverParams spaced;
  spaced.tf_prefix = "robot 1";
  try {
    spaced.validate();
    FAIL() << "a tf_prefix with a space passed";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "tf_prefix");
  }
  DriverParams slash_only;
  slash_only.section(devices::base::kBaseSection).base_frame = "/";
  slash_only.tf_prefix = "robot1";
  slash_only.resolveFrames();
  try {
    slash_only.validate();
    FAIL() << "base/base_frame '/' passed";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "base/base_frame");
  }
}

TEST(DriverParams, TrajectoryDefaultsMustNotBeNegative) {
  const std::vector<std::pair<std::string, std::function<void(DriverParams&)>>> cases = {
      {"trajectory/goal_tolerance", [](DriverParams& p) { p.trajectory.goal_tolerance = -0.1; }},
      {"trajectory/goal_time_tolerance",
       [](DriverParams& p) { p.trajectory.goal_time_tolerance = -1; }},
      {"trajectory/path_tolerance", [](DriverParams& p) { p.trajectory.path_tolerance = -1; }},
      {"trajectory/max_velocity", [](DriverParams& p) { p.trajectory.max_velocity = -2; }},
      {"trajectory/max_start_delay", [](DriverParams& p) { p.trajectory.max_start_delay = 0; }},
      {"trajectory/max_start_delay",
       [](DriverParams& p) { p.trajectory.max_start_delay = std::nan(""); }},
  };
  for (const auto& [key, spoil] : cases) {
    DriverParams params;
    spoil(params);
    try {
      params.validate();
      ADD_FAILURE() << key << " accepted";
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.name(), key);
    }
  }
  EXPECT_NO_THROW(DriverParams().validate());
}

TEST(DriverParams, BusJointsAreCheckedAndNamed) {
  const auto withJoints = [] {
    DriverParams p;
    p.section(devices::servo_bus::kServoBusSection).joint_ids = {3, 4};
    p.section(devices::servo_bus::kServoBusSection).joint_names = {"pan", "tilt"};
    return p;
  };
  EXPECT_NO_THROW(withJoints().validate());
  const std::vector<std::pair<std::string, std::function<void(DriverParams&)>>> cases = {
      {"servo_bus/joint_ids",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_ids = {3, 3};
       }},
      {"servo_bus/joint_ids",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_ids = {3, 255};
       }},
      {"servo_bus/joint_names",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_names = {"pan"};
       }},
      {"servo_bus/joint_names",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_names = {"pan", "pan"};
       }},
      {"servo_bus/joint_names",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_names = {"pan", "joint_1"};
       }},  // a body joint
      {"servo_bus/joint_zero_deg",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_zero_deg = {0};
       }},
      {"servo_bus/joint_zero_deg",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_zero_deg = {0, 200};
       }},
      {"servo_bus/joint_directions",
       [](DriverParams& p) {
         p.section(devices::servo_bus::kServoBusSection).joint_directions = {1, 0};
       }},
  };
  for (const auto& [key, spoil] : cases) {
    DriverParams params = withJoints();
    spoil(params);
    try {
      params.validate();
      ADD_FAILURE() << key << " accepted";
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.name(), key) << e.what();
    }
  }
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
