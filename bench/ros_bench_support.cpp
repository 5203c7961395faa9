#include "ros_bench_support.h"

#include <ros/ros.h>

#include <cstdlib>
#include <stdexcept>

namespace serial_robot_driver::bench {

RosMaster::RosMaster(const RunPaths& paths, int port)
    : uri_("http://localhost:" + std::to_string(port)) {
  ::setenv("ROS_MASTER_URI", uri_.c_str(), 1);
  // Keep roscore's and the nodes' log files with the run instead of in ~/.ros.
  ::setenv("ROS_LOG_DIR", (paths.work_dir + "/ros_log").c_str(), 1);
  ::setenv("ROS_HOME", paths.work_dir.c_str(), 1);
  process_ = std::make_unique<ChildProcess>(
      "roscore", std::vector<std::string>{"roscore", "-p", std::to_string(port)},
      paths.log("roscore"));
}

void RosMaster::waitUntilUp(std::chrono::seconds timeout) const {
  const bool up = waitUntil([] { return ros::master::check(); }, timeout);
  if (!up) throw std::runtime_error("roscore at " + uri_ + " did not come up");
}

XmlRpc::XmlRpcValue toXmlRpc(const std::vector<int>& values) {
  XmlRpc::XmlRpcValue list;
  list.setSize(static_cast<int>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) list[static_cast<int>(i)] = values[i];
  return list;
}

XmlRpc::XmlRpcValue toXmlRpc(const std::vector<std::string>& values) {
  XmlRpc::XmlRpcValue list;
  list.setSize(static_cast<int>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) list[static_cast<int>(i)] = values[i];
  return list;
}

DriverProcess::DriverProcess(const RunPaths& paths, const std::string& ns, const ParamList& params,
                             const std::string& program)
    : ns_(ns) {
  // Parameters go through the master rather than `_name:=value` arguments: lists such as
  // body/servo_ids cannot be written on a command line.
  for (const auto& [key, value] : params) {
    ros::param::set("/" + ns_ + "/driver/" + key, value);
  }
  // A program named by its path (another build) runs as is; a name, from the run's bin_dir.
  const std::string path =
      program.find('/') != std::string::npos ? program : paths.bin_dir + "/" + program;
  process_ = std::make_unique<ChildProcess>(
      program + " " + ns_, std::vector<std::string>{path, "__name:=driver", "__ns:=/" + ns_},
      paths.log(ns_));
}

std::unique_ptr<ChildProcess> startRobotSim(const RunPaths& paths, const std::string& label,
                                            const std::vector<std::string>& flags) {
  std::vector<std::string> argv{paths.bin_dir + "/robot_sim"};
  argv.insert(argv.end(), flags.begin(), flags.end());
  return std::make_unique<ChildProcess>(label, argv, paths.log(label));
}

}  // namespace serial_robot_driver::bench
