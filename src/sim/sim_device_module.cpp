#include "serial_robot_driver/sim/sim_device_module.h"

#include <algorithm>
#include <stdexcept>

#include "serial_robot_driver/sim/sim_options.h"

namespace serial_robot_driver::sim {

const SimDeviceModule* findSimDevice(const std::string& name) {
  for (const SimDeviceModule* device : registeredSimDevices()) {
    if (name == device->name) return device;
  }
  return nullptr;
}

std::string flagName(const std::string& device) {
  std::string flag = device;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

std::string optionFlag(const SimDeviceModule& module, const SimDeviceOption& option) {
  if (option.option.rfind("--", 0) == 0) return option.option;
  return "--" + flagName(module.name) + "-" + option.option;
}

std::string linkFlag(const SimDeviceModule& module) {
  const std::string own = module.link_flag;
  return own.empty() ? "--" + flagName(module.name) + "-link" : own;
}

HostedDeviceOptions& SimOptions::device(const std::string& name) {
  const auto found = devices_.find(name);
  if (found != devices_.end()) return found->second;
  const SimDeviceModule* module = findSimDevice(name);
  if (module == nullptr)
    throw std::invalid_argument("robot_sim: no registered device '" + name + "'");
  HostedDeviceOptions& made = devices_[name];
  made.name = name;
  made.enabled = module->hosted_by_default;
  return made;
}

const HostedDeviceOptions* SimOptions::findDevice(const std::string& name) const {
  const auto found = devices_.find(name);
  return found == devices_.end() ? nullptr : &found->second;
}

bool SimOptions::hosts(const std::string& name) const {
  if (const HostedDeviceOptions* options = findDevice(name)) return options->enabled;
  const SimDeviceModule* module = findSimDevice(name);
  return module != nullptr && module->hosted_by_default;
}

}  // namespace serial_robot_driver::sim
