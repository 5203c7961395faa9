#include "serial_robot_driver/ros/driver_node.h"

#include <algorithm>
#include <atomic>
#include <functional>
#include <sstream>

#include "serial_robot_driver/device/device_module.h"
#include "serial_robot_driver/device/e_stop_status.h"
#include "serial_robot_driver/device/link_status.h"
#include "serial_robot_driver/devices/base/base_interface.h"
#include "serial_robot_driver/devices/body/body_interface.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/runtime_tuning.h"
#include "serial_robot_driver/ros/trajectory_server.h"
#include "serial_robot_driver/ros/wire_capture.h"

namespace serial_robot_driver::ros_layer {

/// Logs a port's comings and goings once per event (reader thread), and the USB latency hint.
/// Once the node shuts down, a port going down is the node closing it (or the robot's end going
/// at the same moment): stopping is not losing, so nothing is logged as lost.
class PortMonitor : public device::LinkListener {
 public:
  PortMonitor(const device::SerialLink& link, const std::atomic<bool>& shutting_down)
      : link_(link), shutting_down_(shutting_down) {}

  void onLinkUp() override {
    waiting_logged_ = false;
    const device::LinkStats stats = link_.stats();
    ROS_INFO("port %s connected (low latency: %s)", link_.options().path.c_str(),
             stats.low_latency ? "yes" : "not supported");
    if (stats.latency_timer_ms && *stats.latency_timer_ms > 1) {
      ROS_WARN("port %s: the USB-serial adapter's latency_timer is %d ms, which delays every frame; "
               "set it to 1 ms with a udev rule (see config/99-serial-robot.rules)",
               link_.options().path.c_str(), *stats.latency_timer_ms);
    }
  }
  void onLinkDown() override {
    if (shutting_down_) {
      ROS_DEBUG("port %s closed", link_.options().path.c_str());
      return;
    }
    ROS_WARN("port %s lost (%s); reopening every %.1f s", link_.options().path.c_str(),
             link_.stats().last_error.c_str(), link_.options().reconnect_interval);
    waiting_logged_ = true;  // the retries that follow need no message of their own
  }
  void onOpenFailed(const std::string& error) override {
    if (waiting_logged_ || shutting_down_) return;  // once per outage, not once per retry
    waiting_logged_ = true;
    ROS_WARN("waiting for port %s (%s); retrying every %.1f s", link_.options().path.c_str(),
             error.c_str(), link_.options().reconnect_interval);
  }
  void onFrame(protocol::FrameFamily, const uint8_t*, std::size_t, device::Clock::time_point) override {}

 private:
  const device::SerialLink& link_;
  const std::atomic<bool>& shutting_down_;
  bool waiting_logged_ = false;  // reader thread only
};

namespace {

}  // namespace

DriverNode::DriverNode(ros::NodeHandle nh, ros::NodeHandle private_nh, DriverParams params,
                       device::SerialLink::StreamFactory stream_factory)
    // The updater prefixes every status with the node's name: the private namespace names the
    // driver both as a node and as a nodelet (whose process is the manager).
    : nh_(nh), params_(std::move(params)), diagnostics_(nh, private_nh, private_nh.getNamespace()) {
  // Each status names its own port as hardware_id; this is only the fallback.
  diagnostics_.setHardwareID(params_.port);

  // Devices naming the same path share one port, one reader thread and one framer.
  std::map<std::string, std::vector<const device::DeviceModule*>> users;
  for (const device::DeviceModule* device : device::registeredDevices()) {
    if (params_.enabled(*device)) users[params_.portOf(*device)].push_back(device);
  }
  if (params_.capture) {
    capture_ = std::make_unique<WireCapture>(nh_, params_);
    diagnostics_.add("wire capture", [this](diagnostic_updater::DiagnosticStatusWrapper& s) {
      capture_->diagnose(s);
    });
  }
  for (const auto& [path, use] : users) {
    device::SerialLinkOptions options;
    options.path = path;
    // validate() made every device on a shared port agree on the baud rate.
    options.baud = static_cast<unsigned>(params_.baudOf(*use.front()));
    options.reconnect_interval = params_.reconnect_interval;
    options.framer = device::framerFor(use, params_);
    for (const device::DeviceModule* device : use) {
      if (!device->stale_frame_timeout) continue;
      // The shortest any device on the port asks for.
      const auto timeout = device->stale_frame_timeout(params_);
      if (options.stale_frame_timeout.count() == 0 || timeout < options.stale_frame_timeout) {
        options.stale_frame_timeout = timeout;
      }
    }
    Port port;
    port.link = std::make_unique<device::SerialLink>(options, stream_factory);
    port.monitor = std::make_unique<PortMonitor>(*port.link, shut_down_);
    port.link->addListener(port.monitor.get());
    port.link->setChunkObserver(capture_.get());
    Port& stored = ports_[path] = std::move(port);
    diagnostics_.add("port " + path, [this, &stored](diagnostic_updater::DiagnosticStatusWrapper& s) {
      diagnosePort(stored, s);
    });
  }

  for (const device::DeviceModule* module : device::registeredDevices()) {
    if (!params_.enabled(*module)) continue;
    const RosDeviceModule* ros_side = findInterface(module->name);
    if (ros_side == nullptr) {
      throw ParameterError(std::string(module->name) + "/enabled",
                           "the device has no ROS interface in this build");
    }
    devices_.push_back(ros_side->make(nh_, params_, portFor(params_.portOf(*module))));
    // The device's status carries its registered name.
    DeviceInterface* device = devices_.back().get();
    diagnostics_.add(module->name, [device](diagnostic_updater::DiagnosticStatusWrapper& s) {
      device->diagnose(s);
    });
    device->addDiagnostics(diagnostics_);
  }
  // Connected whenever both devices run: ~base/use_imu_heading can be switched on at runtime.
  connectImuHeading();
  // One trajectory server for the joints of every device, so one goal may span them.
  std::vector<TrajectoryJoints> trajectory_joints;
  for (auto& device : devices_) {
    for (TrajectoryJoints& group : device->trajectoryJoints()) {
      if (!group.joints.empty()) trajectory_joints.push_back(std::move(group));
    }
  }
  if (!trajectory_joints.empty()) {
    trajectory_ = std::make_unique<TrajectoryServer>(nh_, params_, std::move(trajectory_joints));
    for (auto& device : devices_) device->attachTrajectories(trajectory_.get());
  }
  connectMotionQuery();
  connectEStop();
  // The timer's period is the updater's (~diagnostic_period, default 1 s) and it forces the
  // update: update() would skip a tick that fires a hair before the updater's own deadline.
  diagnostics_period_ = diagnostics_.getPeriod();
  // Runtime tuning: a server per group under ~ (~base, ~imu, ...), starting from params_.
  std::vector<DeviceInterface*> tunable;
  for (auto& device : devices_) tunable.push_back(device.get());
  tuning_ =
      std::make_unique<RuntimeTuning>(private_nh, params_, std::move(tunable), trajectory_.get());
  diagnostics_timer_ = nh_.createSteadyTimer(
      ros::WallDuration(diagnostics_period_),
      [this](const ros::SteadyTimerEvent&) { diagnostics_.force_update(); });
}

DriverNode::~DriverNode() { shutdown(); }

void DriverNode::connectImuHeading() {
  // ~base/use_imu_heading (validate() made sure the body is enabled): the body's reader thread
  // hands each frame's IMU yaw straight to the base controller, which only stores it (see
  // kinematics::HeadingFusion). Both interfaces live in devices_, which outlives the links'
  // threads.
  BaseInterface* base = nullptr;
  BodyInterface* body = nullptr;
  for (auto& device : devices_) {
    if (!base) base = dynamic_cast<BaseInterface*>(device.get());
    if (!body) body = dynamic_cast<BodyInterface*>(device.get());
  }
  if (!base || !body) return;
  const bool replaying = !params_.replay_bag.empty();
  body->setImuYawListener([base, replaying](double yaw, device::Clock::time_point arrival) {
    // A replay's arrival times are the recording's; the base loop runs on this machine's clock.
    base->onImuYaw(yaw, replaying ? device::Clock::now() : arrival);
  });
}

void DriverNode::connectMotionQuery() {
  // Whether the robot is held still, for a sensor's calibration (the body's imu/calibrate): asked
  // on that device's reader and service threads; each device answers under its own short lock.
  // devices_ and trajectory_ are complete here and outlive the links' threads and the devices'
  // spinners.
  std::vector<std::pair<std::string, const DeviceInterface*>> named;
  auto device = devices_.begin();
  for (const device::DeviceModule* module : device::registeredDevices()) {
    if (params_.enabled(*module)) named.emplace_back(module->name, (device++)->get());
  }
  const DeviceInterface::MotionQuery query = [named, trajectory = trajectory_.get()] {
    for (const auto& [name, interface] : named) {
      const std::string why = interface->motionInForce();
      if (!why.empty()) return name + ": " + why;
    }
    const std::string trajectories = trajectory ? trajectory->motionInForce() : std::string();
    return trajectories.empty() ? trajectories : "trajectories: " + trajectories;
  };
  for (auto& each : devices_) each->setMotionQuery(query);
}

void DriverNode::connectEStop() {
  // The trajectories stop first, so no trajectory move follows a device's stop.
  if (trajectory_) trajectory_->attachEStop(e_stop_);
  for (auto& device : devices_) device->attachEStop(e_stop_);
  // A latched publisher's last message arrives on connection; queue 10 so no toggle is dropped.
  e_stop_sub_ = subscribeGuarded(nh_, input_refusals_, "e_stop", 10, &DriverNode::onEStop, this,
                                 ros::TransportHints().tcpNoDelay());
  diagnostics_.add("e_stop", [this](diagnostic_updater::DiagnosticStatusWrapper& s) {
    diagnoseEStop(s);
  });
  if (params_.e_stop.start_engaged) {
    // Before the ports start: the base's first frame is already a zero one.
    e_stop_.set(true);
    ROS_WARN(
        "e_stop engaged at start-up (~e_stop/start_engaged): nothing moves until e_stop "
        "false arrives");
  }
}

void DriverNode::onEStop(const std_msgs::Bool::ConstPtr& msg) {
  if (!e_stop_.set(msg->data)) return;
  if (msg->data) {
    ROS_WARN("e_stop engaged: every actuator stopped (base at zero speed, trajectories aborted, "
             "bus servos stopped); motion commands refused until e_stop is false");
  } else {
    ROS_INFO("e_stop released: motion commands obeyed from the next one");
  }
}

void DriverNode::diagnoseEStop(diagnostic_updater::DiagnosticStatusWrapper& status) {
  device::StatusReport report = device::eStopStatus(e_stop_.stats());
  // Node-wide, next to what the e-stop refused: what every input's checks refused.
  device::InputRefusalStats refusals = input_refusals_.stats();
  for (const auto& device : devices_) refusals += device->inputRefusalStats();
  if (trajectory_) refusals += trajectory_->inputRefusalStats();
  device::addInputRefusals(refusals, report);
  writeStatusReport(report, status);
}

device::SerialLink& DriverNode::portFor(const std::string& path) { return *ports_.at(path).link; }

void DriverNode::start() {
  for (auto& [path, port] : ports_) port.link->start();
  for (auto& device : devices_) device->start();
  if (trajectory_) trajectory_->start();
  ROS_INFO("%s", startupSummary().c_str());
}

std::string DriverNode::startupSummary() const {
  // e.g. "driving port /dev/ttyUSB0 (115200 baud: base, body, servo_bus); loop 50 Hz, battery
  // poll 1 Hz, diagnostics every 1 s"
  std::ostringstream text;
  text << "driving";
  const char* separator = " port ";
  for (const auto& [path, port] : ports_) {
    text << separator << path << " (" << port.link->options().baud << " baud:";
    const char* comma = " ";
    for (const device::DeviceModule* device : device::registeredDevices()) {
      if (!params_.enabled(*device) || params_.portOf(*device) != path) continue;
      text << comma << device->name;
      comma = ", ";
    }
    text << ")";
    separator = ", port ";
  }
  if (params_.section(params::kBaseSection).enabled) {
    text << "; loop " << params_.loop_rate << " Hz, battery poll "
         << params_.section(params::kBaseSection).controller.battery_poll_rate << " Hz";
  }
  text << "; diagnostics every " << diagnostics_period_ << " s";
  return text.str();
}

void DriverNode::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  if (tuning_) tuning_->stop();  // no retune while the devices stop
  diagnostics_timer_.stop();
  e_stop_sub_.shutdown();
  if (trajectory_) trajectory_->shutdown();  // goals end before their joints' devices stop
  // Base first: its zero-speed frame goes out while the port is still open.
  for (auto& device : devices_) device->shutdown();
  for (auto& [path, port] : ports_) port.link->stop();
}

void DriverNode::diagnosePort(const Port& port, diagnostic_updater::DiagnosticStatusWrapper& status) {
  writeStatusReport(device::linkStatus(port.link->stats(), port.link->options()), status);
}

}  // namespace serial_robot_driver::ros_layer
