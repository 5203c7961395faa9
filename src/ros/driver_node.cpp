#include "serial_robot_driver/ros/driver_node.h"

#include <atomic>
#include <utility>

#include "serial_robot_driver/core/e_stop_status.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/dds_front/ros2_graph.h"
#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/ros/ros_device_module.h"
#include "serial_robot_driver/ros/runtime_tuning.h"
#include "serial_robot_driver/ros/trajectory_server.h"
#include "serial_robot_driver/ros/wire_capture.h"

namespace serial_robot_driver::ros_layer {

namespace {

/// The core's log lines (core/log.h) as the node's.
void logToRos(core::LogLevel level, const std::string& text) {
  switch (level) {
    case core::LogLevel::kDebug:
      ROS_DEBUG("%s", text.c_str());
      break;
    case core::LogLevel::kInfo:
      ROS_INFO("%s", text.c_str());
      break;
    case core::LogLevel::kWarn:
      ROS_WARN("%s", text.c_str());
      break;
    case core::LogLevel::kError:
      ROS_ERROR("%s", text.c_str());
      break;
  }
}

}  // namespace

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
  core::setLogSink(logToRos);
  core_ = std::make_unique<core::DriverCore>(params_, stream_factory, capture_.get(),
                                             TrajectoryServer::logWarning());
  attachFrontEnds();
  // ~ros2/enabled: the same devices on the ROS 2 graph, named like this node.
  ros2_ = std::make_unique<dds_front::Ros2Graph>(params_, private_nh.getNamespace(), *core_);
  serveTrajectories();
  connectEStop();
  addStatuses();
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

void DriverNode::attachFrontEnds() {
  for (std::size_t i = 0; i < core_->devices().size(); ++i) {
    const std::string& name = core_->deviceNames()[i];
    const RosDeviceModule* ros_side = findInterface(name);
    if (ros_side == nullptr || ros_side->attach == nullptr) {
      throw ParameterError(name + "/enabled", "the device has no ROS interface in this build");
    }
    front_ends_.push_back(ros_side->attach(nh_, params_, *core_->devices()[i]));
  }
}

void DriverNode::addStatuses() {
  for (core::Device::NamedStatus& source : core_->statusSources()) {
    diagnostics_.add(source.name, [report = std::move(source.report)](
                                      diagnostic_updater::DiagnosticStatusWrapper& s) {
      writeStatusReport(report(), s);
    });
  }
}

void DriverNode::serveTrajectories() {
  if (core_->trajectories() == nullptr) return;
  trajectory_ = std::make_unique<TrajectoryServer>(nh_, params_, *core_->trajectories(),
                                                   core_->inputRefusals());
}

void DriverNode::connectEStop() {
  // A latched publisher's last message arrives on connection; queue 10 so no toggle is dropped.
  e_stop_sub_ = subscribeGuarded(nh_, core_->inputRefusals(), "e_stop", 10, &DriverNode::onEStop,
                                 this, ros::TransportHints().tcpNoDelay());
  if (params_.e_stop.start_engaged) {
    ROS_WARN(
        "e_stop engaged at start-up (~e_stop/start_engaged): nothing moves until e_stop "
        "false arrives");
  }
}

void DriverNode::onEStop(const std_msgs::Bool::ConstPtr& msg) {
  if (core_->eStop().set(msg->data)) core::logEStopChange(msg->data);
}

void DriverNode::start() {
  core_->start();
  for (auto& front_end : front_ends_) front_end->start();
  if (trajectory_) trajectory_->start();
  ros2_->start();
  ROS_INFO("%s; diagnostics every %g s", core_->startupSummary().c_str(), diagnostics_period_);
}

void DriverNode::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  if (tuning_) tuning_->stop();  // no retune while the devices stop
  diagnostics_timer_.stop();
  e_stop_sub_.shutdown();
  ros2_->shutdown();                         // no input from the ROS 2 graph either
  if (trajectory_) trajectory_->shutdown();  // goals end before their joints' devices stop
  core_->shutdown();
  for (auto& front_end : front_ends_) front_end->shutdown();
}

}  // namespace serial_robot_driver::ros_layer
