#include "serial_robot_driver/dds_front/dds_device_module.h"

namespace serial_robot_driver::dds_front {

const DdsDeviceModule* findDdsFrontEnd(const std::string& name) {
  for (const DdsDeviceModule* module : registeredDdsFrontEnds()) {
    if (name == module->name) return module;
  }
  return nullptr;
}

}  // namespace serial_robot_driver::dds_front
