#include "serial_robot_driver/core/driver_core.h"

#include <sstream>
#include <utility>

#include "serial_robot_driver/core/e_stop_status.h"
#include "serial_robot_driver/core/link_status.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/transport/tcp_stream.h"

namespace serial_robot_driver::core {

namespace {

/// The driver's MotionQuery (device/capabilities.h): each enabled device's motionInForce() under
/// its registered name, in the devices' order, then the trajectories'.
class DriverMotion : public MotionQuery {
 public:
  void add(std::string name, const Device* device) {
    devices_.emplace_back(std::move(name), device);
  }
  void setTrajectories(trajectory::TrajectoryExecutor* executor) { trajectories_ = executor; }

  std::string motionInForce() const override {
    for (const auto& [name, device] : devices_) {
      const std::string why = device->motionInForce();
      if (!why.empty()) return name + ": " + why;
    }
    const std::string trajectories = trajectories_ ? trajectories_->motionInForce() : std::string();
    return trajectories.empty() ? trajectories : "trajectories: " + trajectories;
  }
  bool inMotion() const override {
    for (const auto& entry : devices_) {
      if (entry.second->inMotion()) return true;
    }
    return trajectories_ && trajectories_->inMotion();
  }

 private:
  std::vector<std::pair<std::string, const Device*>> devices_;
  trajectory::TrajectoryExecutor* trajectories_ = nullptr;
};

}  // namespace

DriverCore::DriverCore(const params::DriverParams& params, SerialLink::StreamFactory stream_factory,
                       ChunkObserver* observer, trajectory::TrajectoryExecutor::Warn warn)
    : DriverCore(params, MakeDevice(), std::move(stream_factory), observer, std::move(warn)) {}

DriverCore::DriverCore(const params::DriverParams& params, const MakeDevice& make_device,
                       SerialLink::StreamFactory stream_factory, ChunkObserver* observer,
                       trajectory::TrajectoryExecutor::Warn warn)
    : params_(params) {
  openPorts(stream_factory, observer);
  makeDevices(make_device);
  connectTrajectories(std::move(warn));
  // The heading for odometry can be switched on at runtime: offered whenever a device measures it.
  connectCapabilities();
  connectEStop();
}

DriverCore::~DriverCore() { shutdown(); }

void DriverCore::openPorts(const SerialLink::StreamFactory& stream_factory,
                           ChunkObserver* observer) {
  // Devices naming the same path share one port, one reader thread and one framer.
  std::map<std::string, std::vector<const DeviceModule*>> users;
  for (const DeviceModule* device : registeredDevices()) {
    if (params_.enabled(*device)) users[params_.portOf(*device)].push_back(device);
  }
  for (const auto& [path, use] : users) {
    auto link = std::make_unique<SerialLink>(linkOptions(path, use), stream_factory);
    link->setChunkObserver(observer);
    port_logs_.push_back(std::make_unique<PortLog>(*link, shutting_down_));
    link->addListener(port_logs_.back().get());
    ports_[path] = std::move(link);
  }
}

SerialLinkOptions DriverCore::linkOptions(const std::string& path,
                                          const std::vector<const DeviceModule*>& users) const {
  SerialLinkOptions options;
  options.path = path;
  // validate() made every device on a shared port agree on the baud rate.
  options.baud = static_cast<unsigned>(params_.baudOf(*users.front()));
  options.reconnect_interval = params_.reconnect_interval;
  options.realtime_priority = params_.realtime_priority;
  options.scheduler_slice_us = params_.scheduler_slice_us;
  options.framer = framerFor(users, params_);
  for (const DeviceModule* device : users) {
    if (!device->stale_frame_timeout) continue;
    // The shortest any device on the port asks for.
    const auto timeout = device->stale_frame_timeout(params_);
    if (options.stale_frame_timeout.count() == 0 || timeout < options.stale_frame_timeout) {
      options.stale_frame_timeout = timeout;
    }
  }
  return options;
}

void DriverCore::makeDevices(const MakeDevice& make_device) {
  for (const DeviceModule* module : registeredDevices()) {
    if (!params_.enabled(*module)) continue;
    SerialLink& link = *ports_.at(params_.portOf(*module));
    if (make_device) {
      devices_.push_back(make_device(*module, link));
    } else if (module->make_device) {
      devices_.push_back(module->make_device(params_, link));
    } else {
      throw params::ParameterError(std::string(module->name) + "/enabled",
                                   "the device has no driver in this build");
    }
    device_names_.emplace_back(module->name);
  }
}

void DriverCore::connectTrajectories(trajectory::TrajectoryExecutor::Warn warn) {
  // One executor for the joints of every device, so one goal may span them.
  std::vector<trajectory::TrajectoryJoints> trajectory_joints;
  for (auto& device : devices_) {
    for (trajectory::TrajectoryJoints& group : device->trajectoryJoints()) {
      if (!group.joints.empty()) trajectory_joints.push_back(std::move(group));
    }
  }
  if (trajectory_joints.empty()) return;
  trajectories_ = std::make_unique<trajectory::TrajectoryExecutor>(
      std::move(trajectory_joints), params_.trajectory, trajectory::steadyNow, std::move(warn));
  for (auto& device : devices_) device->attachTrajectories(*trajectories_);
}

void DriverCore::connectCapabilities() {
  // Whether the robot is held still, for a sensor's calibration: asked on that device's reader and
  // service threads; each device answers under its own short lock. devices_ and the executor are
  // complete here and outlive the links' threads and the devices' spinners.
  auto motion = std::make_unique<DriverMotion>();
  for (std::size_t i = 0; i < devices_.size(); ++i)
    motion->add(device_names_[i], devices_[i].get());
  motion->setTrajectories(trajectories_.get());
  Capabilities capabilities;
  capabilities.offer<MotionQuery>(*motion);
  motion_ = std::move(motion);
  for (auto& device : devices_) device->offerCapabilities(capabilities);
  for (auto& device : devices_) device->useCapabilities(capabilities);
}

void DriverCore::connectEStop() {
  // The trajectories stop first, so no trajectory move follows a device's stop.
  if (trajectories_) trajectories_->attachEStop(e_stop_);
  for (auto& device : devices_) device->attachEStop(e_stop_);
  // Before the ports start: the base's first frame is already a zero one.
  if (params_.e_stop.start_engaged) e_stop_.set(true);
}

std::vector<Device*> DriverCore::devicePointers() const {
  std::vector<Device*> pointers;
  for (const auto& device : devices_) pointers.push_back(device.get());
  return pointers;
}

Device* DriverCore::device(const std::string& name) const {
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    if (device_names_[i] == name) return devices_[i].get();
  }
  return nullptr;
}

void DriverCore::start() {
  // Before any thread that takes the priority starts: their stacks are locked with the rest.
  realtime_ = prepareRealtime(params_.realtime_priority);
  // Once, whichever front ends run: what applies, or what refused it and how to allow it.
  if (!realtime_.message.empty()) {
    log(realtime_.refused ? LogLevel::kWarn : LogLevel::kInfo, "%s", realtime_.message.c_str());
  }
  if (realtime_.priority == 0) {  // under SCHED_FIFO the frame threads have no slice
    const std::string slice = probeSchedulerSlice(params_.scheduler_slice_us);
    if (!slice.empty()) log(LogLevel::kInfo, "%s", slice.c_str());
  }
  for (auto& [path, link] : ports_) link->start();
  for (auto& device : devices_) device->start();
}

void DriverCore::shutdown() {
  if (shutting_down_.exchange(true)) return;
  // Base first: its zero-speed frame goes out while the port is still open.
  for (auto& device : devices_) device->shutdown();
  for (auto& [path, link] : ports_) link->stop();
}

StatusReport DriverCore::eStopStatus() const {
  StatusReport report = core::eStopStatus(e_stop_.stats());
  // Node-wide, next to what the e-stop refused: what every input's checks refused.
  InputRefusalStats own = input_refusals_.stats();
  for (const auto& device : devices_) own += device->inputRefusalStats();
  addInputRefusals(own, report);
  return report;
}

std::vector<Device::NamedStatus> DriverCore::statusSources() const {
  std::vector<Device::NamedStatus> sources;
  for (const auto& [path, link_ptr] : ports_) {
    const SerialLink* link = link_ptr.get();
    sources.push_back(
        {"port " + path, [link] { return linkStatus(link->stats(), link->options()); }});
  }
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    Device* device = devices_[i].get();
    sources.push_back({device_names_[i], [device] { return device->status(); }});
    for (Device::NamedStatus& extra : device->extraStatuses()) sources.push_back(std::move(extra));
  }
  sources.push_back({"e_stop", [this] { return eStopStatus(); }});
  return sources;
}

std::string DriverCore::startupSummary() const {
  std::ostringstream text;
  text << "driving";
  const char* separator = " port ";
  for (const auto& [path, link] : ports_) {
    // Over TCP the serial server sets the line's baud: naming ~baud there would mislead.
    text << separator << path << " (";
    if (transport::isTcpUrl(path)) {
      text << "TCP:";
    } else {
      text << link->options().baud << " baud:";
    }
    const char* comma = " ";
    for (std::size_t i = 0; i < devices_.size(); ++i) {
      if (params_.portOf(*findDevice(device_names_[i])) != path) continue;
      text << comma << device_names_[i];
      comma = ", ";
    }
    text << ")";
    separator = ", port ";
  }
  for (const auto& device : devices_) {
    const std::string rates = device->startupSummary();
    if (!rates.empty()) text << "; " << rates;
  }
  return text.str();
}

}  // namespace serial_robot_driver::core
