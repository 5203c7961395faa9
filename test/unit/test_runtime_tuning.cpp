// Runtime tuning without a ROS master: the .cfg files (their generated Config classes) against the
// parameter table (every tunable's default, minimum and maximum are the table's and validate()'s;
// every choice of an enum is a value the table accepts), where the .cfg files are and who starts
// their servers, and tuneParams(), which decides what of a requested change applies.
#include <gtest/gtest.h>

#include <boost/any.hpp>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <regex>
#include <set>

#include "serial_robot_driver/BaseTuningConfig.h"
#include "serial_robot_driver/ImuTuningConfig.h"
#include "serial_robot_driver/ServoBusTuningConfig.h"
#include "serial_robot_driver/TrajectoryTuningConfig.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/runtime_tuning.h"

namespace serial_robot_driver::ros_layer {
namespace {

const ParamSpec& specFor(const std::string& key) {
  for (const ParamSpec& spec : parameterTable()) {
    if (spec.key == key) return spec;
  }
  throw std::invalid_argument(key);
}

/// Whether the table's own check of `key` accepts `value` (other parameters at their defaults).
bool tableAccepts(const std::string& key, const ParamValue& value) {
  DriverParams params;
  try {
    specFor(key).set(params, value);  // a converted row checks the value as written here
    specFor(key).check(params);
    return true;
  } catch (const ParameterError& error) {
    EXPECT_EQ(error.name(), key);
    return false;
  }
}

/// The value of a Config's parameter as the table's type.
template <typename Config, typename Description>
ParamValue valueOf(const Config& config, const Description& description) {
  boost::any any;
  description->getValue(config, any);
  if (description->type == "bool") return boost::any_cast<bool>(any);
  if (description->type == "int") return boost::any_cast<int>(any);
  if (description->type == "double") return boost::any_cast<double>(any);
  return boost::any_cast<std::string>(any);
}

/// The values of an enum's choices, from the edit_method text dynamic_reconfigure generates
/// ("{'enum': [{'name': 'stop', 'type': 'str', 'value': 'stop', ...}, ...]"); empty: no enum.
std::vector<ParamValue> enumValues(const std::string& edit_method, const std::string& type) {
  std::vector<ParamValue> values;
  const std::regex value_entry("'value': ('([^']*)'|[-0-9.eE+]+)");
  for (auto it = std::sregex_iterator(edit_method.begin(), edit_method.end(), value_entry);
       it != std::sregex_iterator(); ++it) {
    const std::string text = (*it)[1].str();
    if (type == "str") values.emplace_back((*it)[2].str());
    if (type == "int") values.emplace_back(std::stoi(text));
    if (type == "double") values.emplace_back(std::stod(text));
  }
  return values;
}

/// Every parameter of Config is the table's `<group>/<name>` with the table's type and default,
/// and its range is the table's: the table accepts the minimum (or, for a bound that must be
/// exceeded such as "> 0", the next value up) and the maximum, and refuses the values beyond.
/// A .cfg minimum below what the table accepts would let dynamic_reconfigure offer values the
/// node then refuses. An enum's choices are all values the table accepts.
template <typename Config>
void expectAgreesWithTheTable(const std::string& group, const std::set<std::string>& tunables) {
  std::set<std::string> names;
  const DriverParams defaults;
  for (const auto& description : Config::__getParamDescriptions__()) {
    const std::string key = group + "/" + description->name;
    SCOPED_TRACE(key);
    names.insert(description->name);
    ASSERT_NO_THROW(specFor(key)) << "not a parameter of the table";
    EXPECT_FALSE(description->description.empty());
    const ParamValue table_default = specFor(key).get(defaults);
    const ParamValue cfg_default = valueOf(Config::__getDefault__(), description);
    EXPECT_EQ(cfg_default.index(), table_default.index()) << "type differs";
    EXPECT_EQ(toText(cfg_default), toText(table_default)) << "default differs";
    EXPECT_TRUE(tableAccepts(key, cfg_default));
    for (const ParamValue& choice : enumValues(description->edit_method, description->type)) {
      EXPECT_TRUE(tableAccepts(key, choice)) << "enum choice " << toText(choice);
    }
    if (description->type == "int") {
      const int min = std::get<int>(valueOf(Config::__getMin__(), description));
      const int max = std::get<int>(valueOf(Config::__getMax__(), description));
      EXPECT_TRUE(tableAccepts(key, min));
      EXPECT_FALSE(tableAccepts(key, min - 1));
      EXPECT_TRUE(tableAccepts(key, max));
      EXPECT_FALSE(tableAccepts(key, max + 1));
    } else if (description->type == "double") {
      const double min = std::get<double>(valueOf(Config::__getMin__(), description));
      const double max = std::get<double>(valueOf(Config::__getMax__(), description));
      ASSERT_TRUE(std::isfinite(min)) << "the table bounds every number below";
      const double up = std::nextafter(min, std::numeric_limits<double>::infinity());
      EXPECT_TRUE(tableAccepts(key, min) || tableAccepts(key, up));
      EXPECT_FALSE(
          tableAccepts(key, std::nextafter(min, -std::numeric_limits<double>::infinity())));
      if (std::isfinite(max)) {
        EXPECT_TRUE(tableAccepts(key, max));
        EXPECT_FALSE(
            tableAccepts(key, std::nextafter(max, std::numeric_limits<double>::infinity())));
      } else {
        EXPECT_TRUE(tableAccepts(key, 1e9)) << "no maximum in the .cfg, none in the table";
      }
    }
  }
  EXPECT_EQ(names, tunables);
}

TEST(RuntimeTuningTable, BaseServerHasEveryBaseTunableAsTheTableHasIt) {
  expectAgreesWithTheTable<serial_robot_driver::BaseTuningConfig>(
      "base", {"max_wheel_speed", "max_wheel_accel", "cmd_vel_timeout", "speed_dithering",
               "wheel_diameter", "wheel_separation", "battery_poll_rate", "battery_warn_percent",
               "battery_error_percent", "publish_tf", "use_imu_heading"});
}

TEST(RuntimeTuningTable, ImuServerHasTheScalesAsTheTableHasThem) {
  expectAgreesWithTheTable<serial_robot_driver::ImuTuningConfig>(
      "imu", {"accel_scale", "gyro_scale", "angle_scale", "calibration_time"});
}

TEST(RuntimeTuningTable, ServoBusServerHasEveryBusTunableAsTheTableHasIt) {
  expectAgreesWithTheTable<serial_robot_driver::ServoBusTuningConfig>(
      "servo_bus", {"timeout", "retries", "state_rate", "command_interval_ms", "health_rate",
                    "protect", "relax_power_mw", "on_shutdown"});
}

TEST(RuntimeTuningTable, TrajectoryServerHasTheGoalDefaultsAsTheTableHasThem) {
  expectAgreesWithTheTable<serial_robot_driver::TrajectoryTuningConfig>(
      "trajectory", {"goal_tolerance", "goal_time_tolerance", "path_tolerance", "max_velocity",
                     "max_start_delay"});
}

// The .cfg files are where CMake looks for them (each device's src/devices/<name>/ros/, the node's
// cfg/), each is tested above, and a device has a .cfg exactly when its ROS module starts tuning
// servers (RosDeviceModule::add_tuning), so no group is left without its server or its test.
TEST(RuntimeTuningTable, EveryCfgFileIsInItsDevicesFolderAndTestedAbove) {
  namespace fs = std::filesystem;
  const fs::path sources = SRD_SOURCE_DIR;
  std::map<std::string, std::string> found;  // file name -> folder, relative to the sources
  const auto collect = [&](const fs::path& folder) {
    if (!fs::is_directory(folder)) return;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.path().extension() != ".cfg") continue;
      found[entry.path().filename().string()] = fs::relative(folder, sources).string();
    }
  };
  collect(sources / "cfg");
  for (const ros_layer::RosDeviceModule* module : ros_layer::registeredInterfaces()) {
    SCOPED_TRACE(module->name);
    const fs::path folder = sources / "src/devices" / module->name / "ros";
    const std::size_t before = found.size();
    collect(folder);
    EXPECT_EQ(module->add_tuning != nullptr, found.size() > before)
        << "a device with a tuning .cfg starts its server, and only such a device";
  }
  const std::map<std::string, std::string> tested{
      {"BaseTuning.cfg", "src/devices/base/ros"},
      {"ImuTuning.cfg", "src/devices/body/ros"},
      {"ServoBusTuning.cfg", "src/devices/servo_bus/ros"},
      {"TrajectoryTuning.cfg", "cfg"}};
  EXPECT_EQ(found, tested);
}

TEST(RuntimeTuningTable, TheEnumChoicesAreRead) {
  const auto& descriptions = serial_robot_driver::ServoBusTuningConfig::__getParamDescriptions__();
  for (const auto& description : descriptions) {
    if (description->name != "on_shutdown") continue;
    EXPECT_EQ(
        enumValues(description->edit_method, description->type),
        (std::vector<ParamValue>{std::string("stop"), std::string("relax"), std::string("none")}));
    return;
  }
  ADD_FAILURE() << "no on_shutdown";
}

TEST(TuneParams, AValidChangeApplies) {
  const DriverParams in_force;
  const TuningResult result =
      tuneParams(in_force, {{"base/max_wheel_speed", 0.5}, {"base/wheel_separation", 0.5}});
  EXPECT_TRUE(result.refusals.empty());
  EXPECT_DOUBLE_EQ(result.applied.section(devices::base::kBaseSection).controller.max_wheel_speed,
                   0.5);
  EXPECT_DOUBLE_EQ(
      result.applied.section(devices::base::kBaseSection).controller.geometry.wheel_separation,
      0.5);
  EXPECT_DOUBLE_EQ(
      result.applied.section(devices::base::kBaseSection).controller.geometry.wheel_diameter,
      in_force.section(devices::base::kBaseSection).controller.geometry.wheel_diameter);
}

// What changes is what RuntimeTuning logs and hands to the devices: nothing when the request
// only repeats the values in force or is refused.
TEST(TuneParams, ChangesListEachValueThatDiffersFromTheValueInForce) {
  DriverParams in_force;
  in_force.section(devices::base::kBaseSection).controller.max_wheel_speed = 0.8;
  const TuningResult result = tuneParams(
      in_force,
      {{"base/max_wheel_speed", 0.5},
       {"base/wheel_separation",
        in_force.section(devices::base::kBaseSection).controller.geometry.wheel_separation},
       {"base/cmd_vel_timeout", 0.0}});
  EXPECT_EQ(result.changes, std::vector<std::string>{"~base/max_wheel_speed = 0.5 (was 0.8)"});
  EXPECT_TRUE(tuneParams(in_force, {{"base/max_wheel_speed", 0.8}}).changes.empty());
  EXPECT_TRUE(tuneParams(in_force, {{"base/max_wheel_speed", 0.0}}).changes.empty());
}

TEST(TuneParams, AValueTheStartUpCheckRefusesKeepsTheValueInForce) {
  DriverParams in_force;
  in_force.section(devices::base::kBaseSection).controller.cmd_vel_timeout = 0.8;
  const TuningResult result =
      tuneParams(in_force, {{"base/cmd_vel_timeout", 0.0}, {"base/max_wheel_speed", 0.3}});
  EXPECT_DOUBLE_EQ(result.applied.section(devices::base::kBaseSection).controller.cmd_vel_timeout,
                   0.8);
  EXPECT_DOUBLE_EQ(result.applied.section(devices::base::kBaseSection).controller.max_wheel_speed,
                   0.3)
      << "the valid part applies";
  ASSERT_EQ(result.refusals.size(), 1u);
  EXPECT_NE(result.refusals[0].find("~base/cmd_vel_timeout = 0 refused"), std::string::npos)
      << result.refusals[0];
  EXPECT_NE(result.refusals[0].find("> 0"), std::string::npos) << "says why";
  EXPECT_NE(result.refusals[0].find("keeping 0.8"), std::string::npos) << result.refusals[0];
}

// The speed limit cannot be switched off: the .cfg's minimum (where dynamic_reconfigure clamps a
// negative request) is 0, which the table refuses, so the limit in force stays.
TEST(TuneParams, ASpeedLimitOfZeroOrLessIsRefusedAndTheLimitInForceStays) {
  const auto& description = [] {
    for (const auto& d : serial_robot_driver::BaseTuningConfig::__getParamDescriptions__()) {
      if (d->name == "max_wheel_speed") return d;
    }
    throw std::invalid_argument("max_wheel_speed");
  }();
  const ParamValue cfg_min =
      valueOf(serial_robot_driver::BaseTuningConfig::__getMin__(), description);
  EXPECT_EQ(std::get<double>(cfg_min), 0.0);
  EXPECT_FALSE(tableAccepts("base/max_wheel_speed", cfg_min));

  DriverParams in_force;
  in_force.section(devices::base::kBaseSection).controller.max_wheel_speed = 0.8;
  for (const double requested : {0.0, -1.0}) {
    SCOPED_TRACE(requested);
    const TuningResult result = tuneParams(in_force, {{"base/max_wheel_speed", requested}});
    EXPECT_DOUBLE_EQ(result.applied.section(devices::base::kBaseSection).controller.max_wheel_speed,
                     0.8);
    ASSERT_EQ(result.refusals.size(), 1u);
    EXPECT_NE(result.refusals[0].find("~base/max_wheel_speed = "), std::string::npos)
        << result.refusals[0];
    EXPECT_NE(result.refusals[0].find("> 0"), std::string::npos) << result.refusals[0];
    EXPECT_NE(result.refusals[0].find("keeping 0.8"), std::string::npos) << result.refusals[0];
  }
}

TEST(TuneParams, ARuleBetweenValuesRefusesTheWholeChange) {
  const DriverParams in_force;  // warn 20, error 10
  const TuningResult result =
      tuneParams(in_force, {{"base/battery_warn_percent", 5}, {"base/battery_error_percent", 10}});
  EXPECT_EQ(result.applied.section(devices::base::kBaseSection).battery_warn_percent, 20);
  ASSERT_EQ(result.refusals.size(), 1u);
  EXPECT_NE(result.refusals[0].find("battery_warn_percent = 5 refused"), std::string::npos);
  EXPECT_NE(result.refusals[0].find("must not exceed"), std::string::npos) << result.refusals[0];

  const TuningResult both =
      tuneParams(in_force, {{"base/battery_warn_percent", 5}, {"base/battery_error_percent", 3}});
  EXPECT_TRUE(both.refusals.empty()) << "lowered together, both apply";
  EXPECT_EQ(both.applied.section(devices::base::kBaseSection).battery_warn_percent, 5);
  EXPECT_EQ(both.applied.section(devices::base::kBaseSection).battery_error_percent, 3);
}

TEST(TuneParams, PollRateAboveTheLoopRateAndImuHeadingWithoutTheBodyAreRefused) {
  DriverParams in_force;
  in_force.loop_rate = 20;
  EXPECT_EQ(tuneParams(in_force, {{"base/battery_poll_rate", 25.0}})
                .applied.section(devices::base::kBaseSection)
                .controller.battery_poll_rate,
            in_force.section(devices::base::kBaseSection).controller.battery_poll_rate);
  in_force.section(devices::body::kBodySection).enabled = false;
  const TuningResult result = tuneParams(in_force, {{"base/use_imu_heading", true}});
  EXPECT_FALSE(result.applied.section(devices::base::kBaseSection).controller.use_imu_heading);
  EXPECT_EQ(result.refusals.size(), 1u);
}

TEST(TuneParams, UnknownKeysAndWrongTypesAreProgrammingErrors) {
  EXPECT_THROW(tuneParams(DriverParams{}, {{"base/no_such", 1.0}}), std::invalid_argument);
  EXPECT_THROW(tuneParams(DriverParams{}, {{"base/max_wheel_speed", 1}}), std::invalid_argument);
}

}  // namespace
}  // namespace serial_robot_driver::ros_layer
