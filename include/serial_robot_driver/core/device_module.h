// What makes a device known to the driver: one DeviceModule per device, defined in the device's
// own folder (src/devices/<name>/) and registered by one line in cmake/devices.cmake. The framer
// configuration, the parameter table and its checks, the devices DriverCore builds, their front
// ends (ros/ros_device_module.h) and the simulator (sim/sim_device_module.h) all walk the
// registered modules; none of them names a device. A module is declared with named fields
// (designated initialisers); a field left out is empty or null.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"

namespace serial_robot_driver::params {
class AnySectionKey;
struct DriverParams;
struct ParamSpec;
}  // namespace serial_robot_driver::params

namespace serial_robot_driver::core {

class Device;
class SerialLink;

struct DeviceModule {
  /// The parameter namespace (~<name>/enabled, ~<name>/port, ~<name>/baud and the device's own),
  /// the diagnostic status ("<node>: <name>") and the simulator's name for its link.
  const char* name = nullptr;
  /// For people: the diagnostics analyzer's path ("Servo bus").
  const char* title = nullptr;
  /// What the driver's framer accepts on the device's port: the device's frames, and on a
  /// half-duplex line the echo of the driver's own requests (framed, then ignored, so that they
  /// cannot hide an answer).
  std::vector<protocol::FrameFamily> driver_frames;
  /// What the simulated device reads: the driver's frames to it.
  std::vector<protocol::FrameFamily> simulator_frames;
  /// The keys of the device's parameter sections (params/device_sections.h), which DriverParams
  /// holds with their defaults: first its own section, called like the device, whose struct
  /// derives from params::DevicePortParams (~<name>/enabled, port, baud); then any other it owns
  /// (the body's ~imu/...).
  std::vector<const params::AnySectionKey*> sections;
  /// Appends the device's rows (keys "<name>/...", and those of its other sections) to the table.
  void (*add_parameters)(std::vector<params::ParamSpec>& table) = nullptr;
  /// Checks that relate several values (one value's range is its row's check); throws
  /// params::ParameterError. Called only while the device is enabled. May be null.
  void (*validate)(const params::DriverParams& params) = nullptr;
  /// Puts the device's frame parameters under ~tf_prefix (params::resolveFrame). May be null.
  void (*resolve_frames)(params::DriverParams& params) = nullptr;
  /// The argument the driver's framer passes to the probes of driver_frames (the telemetry's
  /// servo count); null: 0.
  std::size_t (*probe_argument)(const params::DriverParams& params) = nullptr;
  /// How long an incomplete frame may hold back the bytes behind it on the device's port before
  /// the framer gives up on it (a request/response bus: no longer than an answer may take);
  /// null: the link's default.
  std::chrono::milliseconds (*stale_frame_timeout)(const params::DriverParams& params) = nullptr;
  /// Builds the device (its core class, e.g. devices::base::BaseDevice) on `link`, before the link
  /// starts; DriverCore owns it. `params` outlives it. Front ends attach to what this returns.
  std::unique_ptr<Device> (*make_device)(const params::DriverParams& params,
                                         SerialLink& link) = nullptr;
};

/// DeviceModule::make_device for a device class constructed from (params, link).
template <typename DeviceClass>
std::unique_ptr<Device> makeDevice(const params::DriverParams& params, SerialLink& link) {
  return std::make_unique<DeviceClass>(params, link);
}

/// The module called `name` in `registry`, or null: one lookup for every registry of a device's
/// sides (its core module here, its ROS and DDS front ends), which name the device alike.
template <typename Module>
const Module* findByName(const std::vector<const Module*>& registry, const std::string& name) {
  for (const Module* module : registry) {
    if (name == module->name) return module;
  }
  return nullptr;
}

/// The registered devices, in start and shutdown order (cmake/devices.cmake: the base first, so
/// its zero-speed frame goes out before anything else stops).
const std::vector<const DeviceModule*>& registeredDevices();
/// The registered device called `name`, or null.
const DeviceModule* findDevice(const std::string& name);

/// What the driver's framer accepts on a port shared by `devices`.
protocol::FramerConfig framerFor(const std::vector<const DeviceModule*>& devices,
                                 const params::DriverParams& params);
/// What the simulator's framer accepts on a port shared by `devices`.
protocol::FramerConfig simulatorFramerFor(const std::vector<const DeviceModule*>& devices);

}  // namespace serial_robot_driver::core
