#include "serial_robot_driver/ros/ros_device_module.h"

#include <string>

#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

void DeviceInterface::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  writeStatusReport(this->status(), status);
}

const RosDeviceModule* findInterface(const std::string& name) {
  for (const RosDeviceModule* module : registeredInterfaces()) {
    if (name == module->name) return module;
  }
  return nullptr;
}

}  // namespace serial_robot_driver::ros_layer
