// The UART bus servos as a device of the driver: their frames, their parameter section and checks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_device.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::servo_bus {
extern const params::SectionKey<ServoBusParams> kServoBusSection{"servo_bus"};
}

namespace serial_robot_driver::devices::servo_bus {

namespace {

using params::DriverParams;
using params::require;

/// A list of bus servo ids: each addressable (255 is the broadcast address), none twice.
void busServoIds(const std::vector<int>& ids, const std::string& key) {
  std::set<int> seen;
  for (int id : ids) {
    require(id >= 0 && id <= 254, key,
            "ids must be 0..254 (255 is broadcast), got " + std::to_string(id));
    require(seen.insert(id).second, key, "id " + std::to_string(id) + " is listed twice");
  }
}

/// Seconds as the bus waits them: whole milliseconds, rounded, and at least 1 ms for any positive
/// value (0 ms would give up on every answer at once). The row's check refuses the rest before.
std::chrono::milliseconds wholeMilliseconds(double seconds) {
  const std::chrono::milliseconds rounded(std::llround(seconds * 1000.0));
  return seconds > 0 ? std::max(rounded, std::chrono::milliseconds(1)) : rounded;
}

// The section's three parts, each with its own rows: the bus's configuration, its client's
// options and the ROS layer's own values.
using Bus = ServoBusConfig;
using Client = ServoBusOptions;
using BusRows = params::SectionRows<Bus>;
using OwnRows = params::SectionRows<ServoBusParams>;

ServoBusParams& section(DriverParams& p) { return p.section(kServoBusSection); }

/// A whole-number row of a uint16_t field of the bus's configuration.
void addUint16(BusRows& rows, const char* name, uint16_t& (*field)(Bus&), params::Rule<int> rule) {
  rows.addConverted<int>(
      name, field, [](int value) { return static_cast<uint16_t>(value); },
      [](uint16_t value) { return int{value}; }, std::move(rule));
}

void addClientRows(std::vector<params::ParamSpec>& table) {
  params::SectionRows<Client>(table, "servo_bus", "servo_bus",
                              [](DriverParams& p) -> Client& { return section(p).bus.client; })
      .addConverted<double>(
          "timeout", [](Client& o) -> std::chrono::milliseconds& { return o.timeout; },
          wholeMilliseconds,
          [](std::chrono::milliseconds ms) { return std::chrono::duration<double>(ms).count(); },
          [](const double& v, const std::string& key) {
            params::positiveNumber(v, key);
            require(v <= 5.0, key, "must be at most 5 s");
          })
      .add("retries", &Client::retries, params::integerWithin(0, 10))
      .add("allow_dangerous_writes", &Client::allow_dangerous_writes);
}

/// Bus servos as named joints; lengths and names are checked in validate().
void addJointRows(OwnRows& own) {
  own.add("joint_ids", &ServoBusParams::joint_ids, busServoIds)
      .add("joint_names", &ServoBusParams::joint_names,
           [](const std::vector<std::string>& names, const std::string& key) {
             std::set<std::string> seen;
             for (const std::string& name : names) {
               require(!name.empty(), key, "a joint name is empty");
               require(seen.insert(name).second, key, "joint '" + name + "' is listed twice");
             }
           })
      .add("joint_zero_deg", &ServoBusParams::joint_zero_deg,
           [](const std::vector<double>& zeros, const std::string& key) {
             for (double zero : zeros) {
               require(std::isfinite(zero) && zero >= -180.0 && zero <= 180.0, key,
                       "must be servo angles within -180..180 deg");
             }
           })
      .add("joint_directions", &ServoBusParams::joint_directions, params::directionList);
}

/// Safe motion, and what every configured servo should report (0: not checked).
void addSafetyRows(BusRows& bus) {
  addUint16(
      bus, "relax_power_mw", [](Bus& c) -> uint16_t& { return c.relax_power_mw; },
      params::integerWithin(0, 65535, "mW"));
  bus.addConverted<std::string>(
      "on_shutdown", [](Bus& c) -> ShutdownAction& { return c.on_shutdown; },
      // Checked before: only a disabled bus's value can be unknown, and it is never used.
      [](const std::string& v) {
        return shutdownActionFromString(v).value_or(ShutdownAction::kStop);
      },
      [](ShutdownAction action) { return std::string(toString(action)); },
      [](const std::string& v, const std::string& key) {
        require(shutdownActionFromString(v).has_value(), key,
                "must be stop, relax or none, got '" + v + "'");
      });
  bus.add("health_rate", &Bus::health_rate, params::numberWithin(0.0, 10.0, "Hz (0: off)"))
      .add("protect", &Bus::protect);
  addUint16(
      bus, "expected_type", [](Bus& c) -> uint16_t& { return c.identity.expected_type; },
      params::integerWithin(0, 65535, "(0: not checked)"));
  addUint16(
      bus, "expected_firmware", [](Bus& c) -> uint16_t& { return c.identity.expected_firmware; },
      params::integerWithin(0, 65535, "(0: not checked)"));
}

void addParameters(std::vector<params::ParamSpec>& table) {
  // In the documented order.
  addClientRows(table);
  BusRows bus(table, "servo_bus", "servo_bus",
              [](DriverParams& p) -> Bus& { return section(p).bus; });
  OwnRows own(table, "servo_bus", "servo_bus", section);
  own.add("state_ids", &ServoBusParams::state_ids, busServoIds);
  bus.add("state_rate", &Bus::poll_rate, [](const double& v, const std::string& key) {
    params::positiveNumber(v, key);
    // Per servo: one servo on a fast line answers about 1000 times a second. What the
    // line cannot deliver of the asked rate is reported in diagnostics.
    require(v <= 1000, key, "must be at most 1000 Hz");
  });
  own.add("command_interval_ms", &ServoBusParams::command_interval_ms,
          params::integerWithin(0, 65535, "ms"));
  addJointRows(own);
  addSafetyRows(bus);
}

void validate(const DriverParams& p) {
  const ServoBusParams& bus = p.section(kServoBusSection);
  const std::size_t n = bus.joint_ids.size();
  const auto requireOnePerJoint = [n](std::size_t size, const std::string& name,
                                      bool may_be_empty) {
    require(size == n || (may_be_empty && size == 0), name,
            "has " + std::to_string(size) + " entries but servo_bus/joint_ids has " +
                std::to_string(n));
  };
  requireOnePerJoint(bus.joint_names.size(), "servo_bus/joint_names", false);
  requireOnePerJoint(bus.joint_zero_deg.size(), "servo_bus/joint_zero_deg", true);
  requireOnePerJoint(bus.joint_directions.size(), "servo_bus/joint_directions", true);
  if (!p.enabled("body")) return;
  const std::vector<std::string>& body_joints = p.section(body::kBodySection).joint_names;
  for (const std::string& name : bus.joint_names) {
    require(std::find(body_joints.begin(), body_joints.end(), name) == body_joints.end(),
            "servo_bus/joint_names",
            "joint '" + name + "' is also a body joint (body/joint_names)");
  }
}

}  // namespace

extern const core::DeviceModule kModule{
    .name = "servo_bus",
    .title = "Servo bus",
    // The bus is half duplex: the driver's own requests come back as an echo.
    .driver_frames = {kResponseFrames, kRequestFrames},
    .simulator_frames = {kRequestFrames},
    .sections = {&kServoBusSection},
    .add_parameters = addParameters,
    .validate = validate,
    // A servo answer must not wait behind a stray header longer than an answer may take.
    .stale_frame_timeout =
        [](const DriverParams& p) {
          return std::max(std::chrono::milliseconds(1),
                          p.section(kServoBusSection).bus.client.timeout);
        },
    .make_device = core::makeDevice<ServoBusDevice>,
};

}  // namespace serial_robot_driver::devices::servo_bus
