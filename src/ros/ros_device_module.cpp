#include "serial_robot_driver/ros/ros_device_module.h"

#include <string>

namespace serial_robot_driver::ros_layer {

const RosDeviceModule* findInterface(const std::string& name) {
  for (const RosDeviceModule* module : registeredInterfaces()) {
    if (name == module->name) return module;
  }
  return nullptr;
}

}  // namespace serial_robot_driver::ros_layer
