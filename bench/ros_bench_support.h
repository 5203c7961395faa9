// ROS helpers of the driver benchmarks: a private roscore for the run, and driver_node / robot_sim
// instances started with their parameters set on that master.
#pragma once

#include <xmlrpcpp/XmlRpcValue.h>

#include <chrono>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench_support.h"

namespace serial_robot_driver::bench {

/// Where the run keeps its executables, pty links and logs.
struct RunPaths {
  std::string bin_dir;   ///< holds driver_node and robot_sim
  std::string work_dir;  ///< pty links, child logs, ROS_LOG_DIR
  std::string log(const std::string& label) const { return work_dir + "/" + label + ".log"; }
  std::string link(const std::string& label) const { return work_dir + "/" + label + ".pty"; }
};

/// roscore on its own port. The constructor points ROS_MASTER_URI (and ROS_LOG_DIR/ROS_HOME) of
/// this process and its children at it; call it before ros::init, and waitUntilUp() after.
class RosMaster {
 public:
  RosMaster(const RunPaths& paths, int port);
  /// Throws std::runtime_error when the master does not answer within `timeout`.
  void waitUntilUp(std::chrono::seconds timeout) const;
  const std::string& uri() const { return uri_; }

 private:
  std::string uri_;
  std::unique_ptr<ChildProcess> process_;
};

using ParamList = std::vector<std::pair<std::string, XmlRpc::XmlRpcValue>>;
XmlRpc::XmlRpcValue toXmlRpc(const std::vector<int>& values);
XmlRpc::XmlRpcValue toXmlRpc(const std::vector<std::string>& values);

/// One driver_node (or `program`: polling_driver_node, or the floor_node that reads the same
/// parameters) in namespace `ns`, named "driver"; `params` are set under its private namespace before it starts.
/// Stopped (SIGINT: it writes its zero-speed frame) on destruction.
class DriverProcess {
 public:
  DriverProcess(const RunPaths& paths, const std::string& ns, const ParamList& params,
                const std::string& program = "driver_node");
  /// A name in the node's namespace, e.g. topic("cmd_vel") = "/<ns>/cmd_vel".
  std::string topic(const std::string& name) const { return "/" + ns_ + "/" + name; }
  pid_t pid() const { return process_->pid(); }
  bool running() const { return process_->running(); }

 private:
  std::string ns_;
  std::unique_ptr<ChildProcess> process_;
};

/// robot_sim with the given flags, its output in the run's log directory.
std::unique_ptr<ChildProcess> startRobotSim(const RunPaths& paths, const std::string& label,
                                            const std::vector<std::string>& flags);

}  // namespace serial_robot_driver::bench
