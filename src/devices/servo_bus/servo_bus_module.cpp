// The UART bus servos as a device of the driver: their frames, their parameter section and checks.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "serial_robot_driver/device/device_module.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

using params::DriverParams;
using params::require;
using params::ServoBusParams;

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

void addParameters(std::vector<params::ParamSpec>& table) {
  // Rows bound into the bus's configuration (ServoBusParams::bus and its client's options) and
  // the ROS layer's own values, in the documented order.
  using S = ServoBusParams;
  using C = device::ServoBusConfig;
  using O = device::ServoBusOptions;
  params::SectionRows<O> client(table, "servo_bus", "servo_bus",
                                [](DriverParams& p) -> O& { return p.servo_bus.bus.client; });
  params::SectionRows<C> bus(table, "servo_bus", "servo_bus",
                             [](DriverParams& p) -> C& { return p.servo_bus.bus; });
  params::SectionRows<S> own(table, "servo_bus", "servo_bus",
                             [](DriverParams& p) -> S& { return p.servo_bus; });
  client
      .addConverted<double>(
          "timeout", [](O& o) -> std::chrono::milliseconds& { return o.timeout; },
          wholeMilliseconds,
          [](std::chrono::milliseconds ms) { return std::chrono::duration<double>(ms).count(); },
          [](const double& v, const std::string& key) {
            params::positiveNumber(v, key);
            require(v <= 5.0, key, "must be at most 5 s");
          })
      .add("retries", &O::retries, params::integerWithin(0, 10))
      .add("allow_dangerous_writes", &O::allow_dangerous_writes);
  own.add("state_ids", &S::state_ids, busServoIds);
  bus.add("state_rate", &C::poll_rate, [](const double& v, const std::string& key) {
    params::positiveNumber(v, key);
    // Per servo: one servo on a fast line answers about 1000 times a second. What the
    // line cannot deliver of the asked rate is reported in diagnostics.
    require(v <= 1000, key, "must be at most 1000 Hz");
  });
  own.add("command_interval_ms", &S::command_interval_ms, params::integerWithin(0, 65535, "ms"))
      // Bus servos as named joints; lengths and names are checked in validate().
      .add("joint_ids", &S::joint_ids, busServoIds)
      .add("joint_names", &S::joint_names,
           [](const std::vector<std::string>& names, const std::string& key) {
             std::set<std::string> seen;
             for (const std::string& name : names) {
               require(!name.empty(), key, "a joint name is empty");
               require(seen.insert(name).second, key, "joint '" + name + "' is listed twice");
             }
           })
      .add("joint_zero_deg", &S::joint_zero_deg,
           [](const std::vector<double>& zeros, const std::string& key) {
             for (double zero : zeros) {
               require(std::isfinite(zero) && zero >= -180.0 && zero <= 180.0, key,
                       "must be servo angles within -180..180 deg");
             }
           })
      .add("joint_directions", &S::joint_directions, params::directionList);
  // Safe motion.
  bus.addConverted<int>(
         "relax_power_mw", [](C& c) -> uint16_t& { return c.relax_power_mw; },
         [](int mw) { return static_cast<uint16_t>(mw); }, [](uint16_t mw) { return int{mw}; },
         params::integerWithin(0, 65535, "mW"))
      .addConverted<std::string>(
          "on_shutdown", [](C& c) -> device::ShutdownAction& { return c.on_shutdown; },
          // Checked before: only a disabled bus's value can be unknown, and it is never used.
          [](const std::string& v) {
            return device::shutdownActionFromString(v).value_or(device::ShutdownAction::kStop);
          },
          [](device::ShutdownAction action) { return std::string(device::toString(action)); },
          [](const std::string& v, const std::string& key) {
            require(device::shutdownActionFromString(v).has_value(), key,
                    "must be stop, relax or none, got '" + v + "'");
          });
  bus.add("health_rate", &C::health_rate, params::numberWithin(0.0, 10.0, "Hz (0: off)"))
      .add("protect", &C::protect);
  // What every configured servo should report (0: not checked).
  bus.addConverted<int>(
         "expected_type", [](C& c) -> uint16_t& { return c.identity.expected_type; },
         [](int type) { return static_cast<uint16_t>(type); },
         [](uint16_t type) { return int{type}; },
         params::integerWithin(0, 65535, "(0: not checked)"))
      .addConverted<int>(
          "expected_firmware", [](C& c) -> uint16_t& { return c.identity.expected_firmware; },
          [](int version) { return static_cast<uint16_t>(version); },
          [](uint16_t version) { return int{version}; },
          params::integerWithin(0, 65535, "(0: not checked)"));
}

void validate(const DriverParams& p) {
  const ServoBusParams& bus = p.servo_bus;
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
  for (const std::string& name : bus.joint_names) {
    const bool body_has_it =
        p.body.enabled && std::find(p.body.joint_names.begin(), p.body.joint_names.end(), name) !=
                              p.body.joint_names.end();
    require(!body_has_it, "servo_bus/joint_names",
            "joint '" + name + "' is also a body joint (body/joint_names)");
  }
}

}  // namespace

extern const device::DeviceModule kModule{
    "servo_bus",
    "Servo bus",
    // The bus is half duplex: the driver's own requests come back as an echo.
    {protocol::servo::kResponseFrames, protocol::servo::kRequestFrames},
    {protocol::servo::kRequestFrames},
    [](DriverParams& p) -> params::DevicePortParams& { return p.servo_bus; },
    addParameters,
    validate,
    nullptr,
    // A servo answer must not wait behind a stray header longer than an answer may take.
    [](const DriverParams& p) {
      return std::max(std::chrono::milliseconds(1), p.servo_bus.bus.client.timeout);
    },
};

}  // namespace serial_robot_driver::devices::servo_bus
