// The driver on a ROS 2 graph: one DDS participant named like the ROS 1 node (dds::NodeOptions),
// the DDS front end of every enabled device attached to the core's devices, and the node's own
// topics: `e_stop` in (the core's one e-stop, whichever graph set it last), `joint_trajectory` in
// (the core's trajectories) and `diagnostics` out
// (the very StatusReports the ROS node publishes). It runs inside driver_node (~ros2/enabled) and
// alone in dds_driver (run_dds_driver.h); it adds no logic of its own.
//
// Threading: subscription callbacks run on the participant's dispatch thread
// (dds/dispatch_thread.h) and call the devices' inputs there; the devices' outputs publish on the
// devices' threads; diagnostics are published by a thread of this class once a second.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/dds/participant.h"
#include "serial_robot_driver/dds/publisher.h"
#include "serial_robot_driver/dds/subscription.h"
#include "serial_robot_driver/dds_front/dds_conversions.h"
#include "serial_robot_driver/dds_front/dds_device_module.h"

namespace serial_robot_driver::dds_front {

/// The participant's options from ~ros2 (domain, peers) and the node's name and namespace.
dds::NodeOptions nodeOptions(const params::Ros2Params& ros2, const std::string& name,
                             const std::string& node_namespace);

class DdsNode {
 public:
  /// Joins the graph and attaches to `core`'s devices; before core.start(). `params` and `core`
  /// outlive this. Throws std::runtime_error (DDS refused something) and std::invalid_argument (a
  /// bad $ROS_DOMAIN_ID). A device without a DDS front end runs without topics here (a warning).
  DdsNode(const params::DriverParams& params, const dds::NodeOptions& options,
          core::DriverCore& core);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  /// After core.start(): publishes diagnostics from then on.
  void start();
  /// Before core.shutdown(): no input is taken from the graph any more and diagnostics stop; the
  /// publishers stay for the devices' last words. Idempotent.
  void shutdown();

  dds::Participant& participant() { return *participant_; }
  /// The statuses as published now (the diagnostics thread's; tests).
  std::vector<NamedReport> statusReports() const;

 private:
  void attachDevices();
  void onEStop(const std_msgs_msg_dds__Bool_& msg);
  /// joint_trajectory: the core's trajectories, as the ROS 1 topic (refused whole when it does
  /// not check out, counted under its name in the core's one count).
  void onJointTrajectory(const trajectory_msgs_msg_dds__JointTrajectory_& msg);
  void publishDiagnosticsUntilStopped();

  const params::DriverParams& params_;
  core::DriverCore& core_;
  std::string status_prefix_;  ///< "driver_node: ", "robot1/driver_node: "
  std::unique_ptr<dds::Participant> participant_;
  std::vector<std::unique_ptr<DeviceFrontEnd>> front_ends_;
  std::vector<core::Device::NamedStatus> status_sources_;  ///< what diagnostics publishes
  std::unique_ptr<dds::Publisher<diagnostic_msgs_msg_dds__DiagnosticArray_>> diagnostics_;
  std::unique_ptr<dds::Subscription<std_msgs_msg_dds__Bool_>> e_stop_;
  /// Null when no device has joints.
  std::unique_ptr<dds::Subscription<trajectory_msgs_msg_dds__JointTrajectory_>> joint_trajectory_;
  std::mutex stop_mutex_;  // guards stopping_
  std::condition_variable stop_;
  bool stopping_ = false;
  std::thread diagnostics_thread_;
};

}  // namespace serial_robot_driver::dds_front
