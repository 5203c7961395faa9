// The driver without its front end: the ports the enabled devices name, the devices on them in the
// registered order, the trajectories over their joints, the wiring between them (the e-stop, the
// capabilities, the MotionQuery over all of them), their start and shutdown order and the ports'
// log lines (core/port_log.h). It builds and owns every device (DeviceModule::make_device), so it
// runs without any front end; a front end (the ROS DriverNode, ...) attaches to the devices before
// start() and adds only its own things around this: status messages, the e_stop topic, the
// trajectory action, runtime tuning.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/core/capabilities.h"
#include "serial_robot_driver/core/device.h"
#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/port_log.h"
#include "serial_robot_driver/core/realtime.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/params/driver_params.h"
#include "serial_robot_driver/trajectory/executor.h"

namespace serial_robot_driver::core {

class DriverCore {
 public:
  /// Builds the device of `module` on `link` (tests: a device of their own).
  using MakeDevice =
      std::function<std::unique_ptr<Device>(const DeviceModule& module, SerialLink& link)>;

  /// Opens nothing yet: builds one SerialLink per path the enabled devices name (`stream_factory`
  /// and `observer` as SerialLink takes them), each enabled device (its module's make_device), one
  /// trajectory executor over their joints (warning through `warn`), and wires the capabilities
  /// and the e-stop. `params` must outlive this. Throws params::ParameterError for an enabled
  /// device that has no make_device.
  explicit DriverCore(const params::DriverParams& params,
                      SerialLink::StreamFactory stream_factory = {},
                      ChunkObserver* observer = nullptr,
                      trajectory::TrajectoryExecutor::Warn warn = {});
  /// The same with the devices built by `make_device` (empty: their modules').
  DriverCore(const params::DriverParams& params, const MakeDevice& make_device,
             SerialLink::StreamFactory stream_factory = {}, ChunkObserver* observer = nullptr,
             trajectory::TrajectoryExecutor::Warn warn = {});
  ~DriverCore();
  DriverCore(const DriverCore&) = delete;
  DriverCore& operator=(const DriverCore&) = delete;

  /// Locks the memory and checks SCHED_FIFO for ~realtime_priority (core/realtime.h; its one line
  /// to the core log), then starts the ports, then the devices.
  void start();
  /// What start() found of ~realtime_priority.
  const RealtimeStatus& realtime() const { return realtime_; }
  /// Shuts the devices down in order (the base first, its last words while the port is still
  /// open), then stops the ports. Idempotent.
  void shutdown();

  /// The ports by path (sorted).
  const std::map<std::string, std::unique_ptr<SerialLink>>& ports() const { return ports_; }
  /// The devices in start and shutdown order, with their registered names.
  const std::vector<std::unique_ptr<Device>>& devices() const { return devices_; }
  const std::vector<std::string>& deviceNames() const { return device_names_; }
  std::vector<Device*> devicePointers() const;
  /// The device of the registered module called `name`, or null when it is not enabled.
  Device* device(const std::string& name) const;
  /// The trajectories over every device's joints; null when no device has any.
  trajectory::TrajectoryExecutor* trajectories() const { return trajectories_.get(); }
  /// What is moving the robot now (device/capabilities.h), as the devices were offered it.
  const MotionQuery& motion() const { return *motion_; }
  /// The one e-stop of every actuator.
  EStop& eStop() { return e_stop_; }

  /// Where every front end counts what it refuses of its own inputs (its e_stop topic, its
  /// trajectories): one count for the node, whichever graph sent the input.
  InputRefusals& inputRefusals() { return input_refusals_; }

  /// The e-stop's status with every input refusal: the devices' and inputRefusals()'.
  StatusReport eStopStatus() const;
  /// Every status a front end reports, in one order for all of them: each port ("port <path>"),
  /// each device (its registered name) followed by its own statuses, then "e_stop". Every front
  /// end's sources report the same values (one e-stop, one count of refusals).
  std::vector<Device::NamedStatus> statusSources() const;
  /// e.g. "driving port /dev/ttyUSB0 (115200 baud: base, body); loop 50 Hz, battery poll 1 Hz".
  std::string startupSummary() const;

 private:
  void openPorts(const SerialLink::StreamFactory& stream_factory, ChunkObserver* observer);
  SerialLinkOptions linkOptions(const std::string& path,
                                const std::vector<const DeviceModule*>& users) const;
  void makeDevices(const MakeDevice& make_device);
  void connectTrajectories(trajectory::TrajectoryExecutor::Warn warn);
  void connectCapabilities();
  void connectEStop();

  const params::DriverParams& params_;
  /// Set when shutdown() begins: the ports' closing is no outage (PortLog). Outlives the ports.
  std::atomic<bool> shutting_down_{false};
  /// Outlives the devices and the trajectories that registered with it.
  EStop e_stop_;
  InputRefusals input_refusals_;                     ///< the front ends' own inputs', every graph's
  std::vector<std::unique_ptr<PortLog>> port_logs_;  ///< one per port; outlive the ports' readers
  std::map<std::string, std::unique_ptr<SerialLink>> ports_;
  /// Outlives the devices, which hold a reference to it.
  std::unique_ptr<trajectory::TrajectoryExecutor> trajectories_;
  /// The MotionQuery the devices were offered; outlives them.
  std::unique_ptr<MotionQuery> motion_;
  std::vector<std::unique_ptr<Device>> devices_;
  std::vector<std::string> device_names_;
  RealtimeStatus realtime_;
};

}  // namespace serial_robot_driver::core
