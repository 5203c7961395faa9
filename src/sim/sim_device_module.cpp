#include "serial_robot_driver/sim/sim_device_module.h"

#include <algorithm>

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

}  // namespace serial_robot_driver::sim
