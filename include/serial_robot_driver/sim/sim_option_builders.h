// Building blocks for the robot_sim flags a device declares (SimDeviceOption): each parses its
// value, checks its range and writes a field of the device's typed settings; command_line.cpp
// uses the same parsers for the robot-wide flags, so every flag reports a bad value alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::sim {

/// A finite number; false for anything else (trailing text included).
bool parseDouble(const std::string& text, double* value);
/// Decimal digits only, up to `max`.
bool parseUnsigned(const std::string& text, uint64_t max, uint64_t* value);
/// Comma-separated ids 0..254.
bool parseIdList(const std::string& text, std::vector<uint8_t>* ids);
/// "bad value for --flag: 'text'".
std::string badValue(const std::string& flag, const std::string& value);
/// How --help shows a default.
std::string showDefault(double value);
std::string showDefault(const std::vector<uint8_t>& ids);

namespace option_detail {
std::string applyNumber(const std::string& flag, const std::string& value, double min, double max,
                        double* field);
std::string applyWhole(const std::string& flag, const std::string& value, uint64_t max,
                       uint64_t* parsed);
std::string applyIdList(const std::string& flag, const std::string& value, std::size_t max_count,
                        const std::string& limit, std::vector<uint8_t>* ids);
std::string applyHeldValue(const std::string& flag, const std::string& value,
                           std::map<uint8_t, int64_t>* values);
}  // namespace option_detail

/// A flag whose value is a number in [min, max], into `field` of the device's `Config`.
template <typename Config>
SimDeviceOption numberOption(const std::string& flag, const std::string& value_name,
                             const std::string& help, double min, double max, double Config::*field,
                             bool show_default) {
  SimDeviceOption option{flag, value_name, help, nullptr, nullptr};
  option.apply = [flag, min, max, field](const std::string& value, HostedDeviceOptions& device) {
    return option_detail::applyNumber(flag, value, min, max, &(device.configAs<Config>().*field));
  };
  if (show_default) {
    option.shown_default = [field](const HostedDeviceOptions& defaults) {
      return showDefault(defaults.configAs<Config>().*field);
    };
  }
  return option;
}

/// A flag whose value is an unsigned integer up to `max`, into the integer `field`.
template <typename Config, typename Integer>
SimDeviceOption wholeOption(const std::string& flag, const std::string& value_name,
                            const std::string& help, uint64_t max, Integer Config::*field,
                            bool show_default) {
  SimDeviceOption option{flag, value_name, help, nullptr, nullptr};
  option.apply = [flag, max, field](const std::string& value, HostedDeviceOptions& device) {
    uint64_t parsed = 0;
    std::string problem = option_detail::applyWhole(flag, value, max, &parsed);
    if (problem.empty()) device.configAs<Config>().*field = static_cast<Integer>(parsed);
    return problem;
  };
  if (show_default) {
    option.shown_default = [field](const HostedDeviceOptions& defaults) {
      return std::to_string(static_cast<uint64_t>(defaults.configAs<Config>().*field));
    };
  }
  return option;
}

/// A flag whose value is a comma-separated list of ids 0..254, at most `max_count` of them
/// (`limit`: why, for the error).
template <typename Config>
SimDeviceOption idListOption(const std::string& flag, const std::string& value_name,
                             const std::string& help, std::size_t max_count,
                             const std::string& limit, std::vector<uint8_t> Config::*field,
                             bool show_default) {
  SimDeviceOption option{flag, value_name, help, nullptr, nullptr};
  option.apply = [flag, max_count, limit, field](const std::string& value,
                                                 HostedDeviceOptions& device) {
    return option_detail::applyIdList(flag, value, max_count, limit,
                                      &(device.configAs<Config>().*field));
  };
  if (show_default) {
    option.shown_default = [field](const HostedDeviceOptions& defaults) {
      return showDefault(defaults.configAs<Config>().*field);
    };
  }
  return option;
}

/// "ID:VALUE" into a per-id map (a held reading); repeatable.
template <typename Config>
SimDeviceOption heldValueOption(const std::string& flag, const std::string& value_name,
                                const std::string& help,
                                std::map<uint8_t, int64_t> Config::*field) {
  SimDeviceOption option{flag, value_name, help, nullptr, nullptr};
  option.apply = [flag, field](const std::string& value, HostedDeviceOptions& device) {
    return option_detail::applyHeldValue(flag, value, &(device.configAs<Config>().*field));
  };
  return option;
}

/// A switch: `set` changes the device's `Config`.
template <typename Config>
SimDeviceOption switchOption(const std::string& flag, const std::string& help,
                             void (*set)(Config&)) {
  SimDeviceOption option{flag, "", help, nullptr, nullptr};
  option.apply = [set](const std::string&, HostedDeviceOptions& device) {
    set(device.configAs<Config>());
    return std::string();
  };
  return option;
}

}  // namespace serial_robot_driver::sim
