#include "serial_robot_driver/core/device_module.h"

namespace serial_robot_driver::core {

const DeviceModule* findDevice(const std::string& name) {
  return findByName(registeredDevices(), name);
}

protocol::FramerConfig framerFor(const std::vector<const DeviceModule*>& devices,
                                 const params::DriverParams& params) {
  protocol::FramerConfig config;
  for (const DeviceModule* device : devices) {
    const std::size_t argument = device->probe_argument ? device->probe_argument(params) : 0;
    for (const protocol::FrameFamily& family : device->driver_frames) {
      config.accept(family, argument);
    }
  }
  return config;
}

protocol::FramerConfig simulatorFramerFor(const std::vector<const DeviceModule*>& devices) {
  protocol::FramerConfig config;
  for (const DeviceModule* device : devices) {
    for (const protocol::FrameFamily& family : device->simulator_frames) config.accept(family);
  }
  return config;
}

}  // namespace serial_robot_driver::core
