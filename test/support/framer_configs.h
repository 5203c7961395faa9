// Framer configurations as the driver and the simulator build them, from the registered devices
// (device/device_module.h): tests and benchmarks name devices, never frame families.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace test_support {

namespace core = serial_robot_driver::core;
namespace params = serial_robot_driver::params;
namespace protocol = serial_robot_driver::protocol;

/// What the driver's framer accepts on a port shared by the devices called `names`, with
/// `body_servos` servos in the body's telemetry.
inline protocol::FramerConfig driverFramer(const std::vector<std::string>& names,
                                           std::size_t body_servos = 0) {
  std::vector<const core::DeviceModule*> devices;
  for (const std::string& name : names) {
    const core::DeviceModule* device = core::findDevice(name);
    if (device == nullptr) throw std::invalid_argument("no registered device " + name);
    devices.push_back(device);
  }
  params::DriverParams params;
  params.section(serial_robot_driver::devices::body::kBodySection).servo_ids.assign(body_servos, 1);
  return core::framerFor(devices, params);
}

/// What the simulator's framer accepts (every registered device's inbound frames).
inline protocol::FramerConfig simulatorFramer() {
  return core::simulatorFramerFor(core::registeredDevices());
}

/// Every frame family of the registered devices, both directions, telemetry of `body_servos`.
inline protocol::FramerConfig everyFamily(std::size_t body_servos) {
  protocol::FramerConfig config = driverFramer({"base", "body", "servo_bus"}, body_servos);
  const protocol::FramerConfig simulator = simulatorFramer();
  for (std::size_t i = 0; i < simulator.family_count; ++i) {
    if (!config.accepts(simulator.families[i].family)) config.accept(simulator.families[i].family);
  }
  return config;
}

}  // namespace test_support
