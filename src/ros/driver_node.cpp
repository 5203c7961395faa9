#include "serial_robot_driver/ros/driver_node.h"

#include <atomic>
#include <utility>

#include "serial_robot_driver/core/link_status.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/device_interface.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/runtime_tuning.h"
#include "serial_robot_driver/ros/trajectory_server.h"
#include "serial_robot_driver/ros/wire_capture.h"

namespace serial_robot_driver::ros_layer {

/// Logs a port's comings and goings once per event (reader thread), and the USB latency hint.
/// Once the node shuts down, a port going down is the node closing it (or the robot's end going
/// at the same moment): stopping is not losing, so nothing is logged as lost.
class PortMonitor : public core::LinkListener {
 public:
  PortMonitor(const core::SerialLink& link, const std::atomic<bool>& shutting_down)
      : link_(link), shutting_down_(shutting_down) {}

  void onLinkUp() override {
    waiting_logged_ = false;
    const core::LinkStats stats = link_.stats();
    ROS_INFO("port %s connected (low latency: %s)", link_.options().path.c_str(),
             stats.low_latency ? "yes" : "not supported");
    if (stats.latency_timer_ms && *stats.latency_timer_ms > 1) {
      ROS_WARN(
          "port %s: the USB-serial adapter's latency_timer is %d ms, which delays every frame; "
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
  void onFrame(protocol::FrameFamily, const uint8_t*, std::size_t,
               core::Clock::time_point) override {}

 private:
  const core::SerialLink& link_;
  const std::atomic<bool>& shutting_down_;
  bool waiting_logged_ = false;  // reader thread only
};

DriverNode::DriverNode(ros::NodeHandle nh, ros::NodeHandle private_nh, DriverParams params,
                       core::SerialLink::StreamFactory stream_factory)
    // The updater prefixes every status with the node's name: the private namespace names the
    // driver both as a node and as a nodelet (whose process is the manager).
    : nh_(nh), params_(std::move(params)), diagnostics_(nh, private_nh, private_nh.getNamespace()) {
  // Each status names its own port as hardware_id; this is only the fallback.
  diagnostics_.setHardwareID(params_.port);
  if (params_.capture) {
    capture_ = std::make_unique<WireCapture>(nh_, params_);
    diagnostics_.add("wire capture", [this](diagnostic_updater::DiagnosticStatusWrapper& s) {
      capture_->diagnose(s);
    });
  }
  core_ = std::make_unique<core::DriverCore>(
      params_,
      [this](const core::DeviceModule& module, core::SerialLink& link) {
        return makeDevice(module, link);
      },
      stream_factory, capture_.get(), TrajectoryServer::logWarning());
  addPortsAndDevices();
  serveTrajectories();
  connectEStop();
  // The timer's period is the updater's (~diagnostic_period, default 1 s) and it forces the
  // update: update() would skip a tick that fires a hair before the updater's own deadline.
  diagnostics_period_ = diagnostics_.getPeriod();
  // Runtime tuning: a server per group under ~ (~base, ~imu, ...), starting from params_.
  tuning_ = std::make_unique<RuntimeTuning>(private_nh, params_, core_->devicePointers(),
                                            core_->trajectories());
  diagnostics_timer_ =
      nh_.createSteadyTimer(ros::WallDuration(diagnostics_period_),
                            [this](const ros::SteadyTimerEvent&) { diagnostics_.force_update(); });
}

DriverNode::~DriverNode() { shutdown(); }

std::unique_ptr<core::Device> DriverNode::makeDevice(const core::DeviceModule& module,
                                                     core::SerialLink& link) {
  const RosDeviceModule* ros_side = findInterface(module.name);
  if (ros_side == nullptr) {
    throw ParameterError(std::string(module.name) + "/enabled",
                         "the device has no ROS interface in this build");
  }
  return ros_side->make(nh_, params_, link);
}

void DriverNode::addPortsAndDevices() {
  for (const auto& [path, link_ptr] : core_->ports()) {
    core::SerialLink& link = *link_ptr;
    port_monitors_.push_back(std::make_unique<PortMonitor>(link, shut_down_));
    link.addListener(port_monitors_.back().get());
    diagnostics_.add("port " + path, [&link](diagnostic_updater::DiagnosticStatusWrapper& s) {
      writeStatusReport(core::linkStatus(link.stats(), link.options()), s);
    });
  }
  for (std::size_t i = 0; i < core_->devices().size(); ++i) {
    // The device's status carries its registered name; its own statuses theirs.
    core::Device* device = core_->devices()[i].get();
    diagnostics_.add(core_->deviceNames()[i],
                     [device](diagnostic_updater::DiagnosticStatusWrapper& s) {
                       writeStatusReport(device->status(), s);
                     });
    for (core::Device::NamedStatus& extra : device->extraStatuses()) {
      diagnostics_.add(extra.name, [report = std::move(extra.report)](
                                       diagnostic_updater::DiagnosticStatusWrapper& s) {
        writeStatusReport(report(), s);
      });
    }
  }
}

void DriverNode::serveTrajectories() {
  if (core_->trajectories() == nullptr) return;
  trajectory_ = std::make_unique<TrajectoryServer>(nh_, params_, *core_->trajectories());
}

void DriverNode::connectEStop() {
  // A latched publisher's last message arrives on connection; queue 10 so no toggle is dropped.
  e_stop_sub_ = subscribeGuarded(nh_, input_refusals_, "e_stop", 10, &DriverNode::onEStop, this,
                                 ros::TransportHints().tcpNoDelay());
  diagnostics_.add("e_stop", [this](diagnostic_updater::DiagnosticStatusWrapper& s) {
    core::InputRefusalStats own = input_refusals_.stats();
    if (trajectory_) own += trajectory_->inputRefusalStats();
    writeStatusReport(core_->eStopStatus(own), s);
  });
  if (params_.e_stop.start_engaged) {
    ROS_WARN(
        "e_stop engaged at start-up (~e_stop/start_engaged): nothing moves until e_stop "
        "false arrives");
  }
}

void DriverNode::onEStop(const std_msgs::Bool::ConstPtr& msg) {
  if (!core_->eStop().set(msg->data)) return;
  if (msg->data) {
    ROS_WARN(
        "e_stop engaged: every actuator stopped (base at zero speed, trajectories aborted, "
        "bus servos stopped); motion commands refused until e_stop is false");
  } else {
    ROS_INFO("e_stop released: motion commands obeyed from the next one");
  }
}

void DriverNode::start() {
  core_->start();
  const core::RealtimeStatus& realtime = core_->realtime();
  if (realtime.refused) {
    ROS_WARN("%s", realtime.message.c_str());
  } else if (!realtime.message.empty()) {
    ROS_INFO("%s", realtime.message.c_str());
  }
  if (trajectory_) trajectory_->start();
  ROS_INFO("%s; diagnostics every %g s", core_->startupSummary().c_str(), diagnostics_period_);
}

void DriverNode::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  if (tuning_) tuning_->stop();  // no retune while the devices stop
  diagnostics_timer_.stop();
  e_stop_sub_.shutdown();
  if (trajectory_) trajectory_->shutdown();  // goals end before their joints' devices stop
  core_->shutdown();
}

}  // namespace serial_robot_driver::ros_layer
