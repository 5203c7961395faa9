// A device's DDS (ROS 2) front end, registered like its ROS one (ros/ros_device_module.h) and
// found by the device's name: DdsNode attaches the front end of every enabled device to the
// device the core built. Defined in the device's folder (src/devices/<name>/dds/), the one place
// that knows the core device's class; built only with Cyclone DDS (SRD_WITH_DDS).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/dds/participant.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::dds_front {

/// A device's topics on the ROS 2 graph: converts samples to the device's inputs and its outputs
/// to samples, nothing more (the checks, the counting and the log lines are the device's).
class DeviceFrontEnd {
 public:
  virtual ~DeviceFrontEnd() = default;
  /// Before the core shuts the devices down: no input reaches the device from then on (its
  /// publishers stay until it is destroyed, after the devices' last words). Idempotent.
  virtual void shutdown() = 0;
};

/// Declared with named fields (designated initialisers).
struct DdsDeviceModule {
  /// The core module's name (DeviceModule::name).
  const char* name = nullptr;
  /// Builds the front end on `device` (made by its core module's make_device) before the core
  /// starts: it registers its outputs with the device. `device` and `participant` outlive it.
  std::unique_ptr<DeviceFrontEnd> (*attach)(dds::Participant& participant,
                                            const params::DriverParams& params,
                                            core::Device& device) = nullptr;
};

/// The registered devices' DDS front ends, in the order of the devices (cmake/devices.cmake).
const std::vector<const DdsDeviceModule*>& registeredDdsFrontEnds();
/// The DDS front end of the device called `name`, or null.
inline const DdsDeviceModule* findDdsFrontEnd(const std::string& name) {
  return core::findByName(registeredDdsFrontEnds(), name);
}

}  // namespace serial_robot_driver::dds_front
