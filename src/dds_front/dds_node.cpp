#include "serial_robot_driver/dds_front/dds_node.h"

#include <chrono>
#include <optional>

#include "serial_robot_driver/core/e_stop_status.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/wall_stamps.h"
#include "serial_robot_driver/dds/ros_conventions.h"
#include "serial_robot_driver/dds_front/guarded_subscription.h"
#include "serial_robot_driver/trajectory/message_time.h"

namespace serial_robot_driver::dds_front {

namespace {
/// diagnostic_updater's default period, which the ROS node keeps unless ~diagnostic_period says.
constexpr std::chrono::seconds kDiagnosticsPeriod{1};
}  // namespace

dds::NodeOptions nodeOptions(const params::Ros2Params& ros2, const std::string& name,
                             const std::string& node_namespace) {
  dds::NodeOptions options;
  options.name = name;
  options.node_namespace = node_namespace;
  options.domain_id = ros2.domain_id;
  options.peers = ros2.peers;
  return options;
}

DdsNode::DdsNode(const params::DriverParams& params, const dds::NodeOptions& options,
                 core::DriverCore& core)
    : params_(params),
      core_(core),
      // As diagnostic_updater names a node's statuses: its full name without the leading slash.
      status_prefix_(dds::fullyQualifiedName(options.node_namespace, options.name).substr(1) +
                     ": "),
      participant_(std::make_unique<dds::Participant>(options)) {
  attachDevices();
  status_sources_ = core_.statusSources();
  diagnostics_ = std::make_unique<dds::Publisher<diagnostic_msgs_msg_dds__DiagnosticArray_>>(
      *participant_, "/diagnostics");
  // Queue 10 as on the ROS side, so no toggle is dropped.
  e_stop_ = subscribeGuarded<std_msgs_msg_dds__Bool_>(
      *participant_, core_.inputRefusals(), "e_stop",
      [this](const std_msgs_msg_dds__Bool_& msg) { onEStop(msg); });
  if (core_.trajectories() != nullptr) {
    joint_trajectory_ = subscribeGuarded<trajectory_msgs_msg_dds__JointTrajectory_>(
        *participant_, core_.inputRefusals(), "joint_trajectory",
        [this](const trajectory_msgs_msg_dds__JointTrajectory_& msg) { onJointTrajectory(msg); });
  }
}

DdsNode::~DdsNode() { shutdown(); }

void DdsNode::attachDevices() {
  for (std::size_t i = 0; i < core_.devices().size(); ++i) {
    const std::string& name = core_.deviceNames()[i];
    const DdsDeviceModule* module = findDdsFrontEnd(name);
    if (module == nullptr) {  // it still runs, and its statuses are in diagnostics
      core::log(core::LogLevel::kWarn, "%s has no topics on the ROS 2 graph (ROS 1 only)",
                name.c_str());
      continue;
    }
    front_ends_.push_back(module->attach(*participant_, params_, *core_.devices()[i]));
  }
}

void DdsNode::onEStop(const std_msgs_msg_dds__Bool_& msg) {
  if (core_.eStop().set(msg.data)) core::logEStopChange(msg.data);
}

void DdsNode::onJointTrajectory(const trajectory_msgs_msg_dds__JointTrajectory_& msg) {
  trajectory::TrajectoryExecutor& executor = *core_.trajectories();
  std::optional<double> start;  // a zero stamp: now
  const trajectory::MessageStamp stamp{msg.header.stamp.sec, msg.header.stamp.nanosec};
  if (!stamp.isZero()) {
    const double executor_now = executor.now();
    const auto wall_now = std::chrono::system_clock::now().time_since_epoch();
    const auto wall_sec = std::chrono::duration_cast<std::chrono::seconds>(wall_now);
    start = trajectory::steadyStart(stamp, executor_now,
                                    {wall_sec.count(), (wall_now - wall_sec).count()});
  }
  if (executor.submitTrajectory(toTrajectoryCommand(msg), start) ==
      trajectory::TrajectoryExecutor::Submission::kInvalid) {
    core_.inputRefusals().refused("joint_trajectory");
  }
}

void DdsNode::start() {
  diagnostics_thread_ = std::thread([this] { publishDiagnosticsUntilStopped(); });
}

void DdsNode::shutdown() {
  {
    std::lock_guard<std::mutex> lock(stop_mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  if (diagnostics_thread_.joinable()) diagnostics_thread_.join();
  e_stop_.reset();
  joint_trajectory_.reset();
  for (auto& front_end : front_ends_) front_end->shutdown();
}

std::vector<NamedReport> DdsNode::statusReports() const {
  std::vector<NamedReport> reports;
  for (const core::Device::NamedStatus& source : status_sources_) {
    reports.emplace_back(status_prefix_ + source.name, source.report());
  }
  return reports;
}

void DdsNode::publishDiagnosticsUntilStopped() {
  std::unique_lock<std::mutex> lock(stop_mutex_);
  while (!stop_.wait_for(lock, kDiagnosticsPeriod, [this] { return stopping_; })) {
    if (!diagnostics_->hasSubscribers()) continue;  // nothing built that nobody reads
    const core::WallStamps stamps;
    const DiagnosticsSample sample(stamps(core::Clock::now()), statusReports(), params_.port);
    diagnostics_->publish(sample.sample());
  }
}

}  // namespace serial_robot_driver::dds_front
