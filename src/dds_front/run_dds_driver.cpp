#include "serial_robot_driver/dds_front/run_dds_driver.h"

#include <chrono>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/core/stop_signals.h"
#include "serial_robot_driver/dds/ros_conventions.h"
#include "serial_robot_driver/dds_front/dds_node.h"
#include "serial_robot_driver/dds_front/trajectory_loop.h"
#include "serial_robot_driver/params/yaml_param_source.h"

namespace serial_robot_driver::dds_front {

std::string ddsDriverUsage() {
  return "usage: dds_driver --config FILE [--name NAME] [--namespace NS]\n"
         "  runs the driver on a ROS 2 graph (DDS), no ROS 1 master: FILE is driver_node's\n"
         "  parameter file (config/robot.yaml); the node is NS/NAME (default /driver_node).\n";
}

DdsDriverOptions parseDdsDriverArguments(int argc, const char* const* argv, bool* help) {
  DdsDriverOptions options;
  *help = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      *help = true;
      return options;
    }
    std::string* value = arg == "--config"      ? &options.config
                         : arg == "--name"      ? &options.name
                         : arg == "--namespace" ? &options.node_namespace
                                                : nullptr;
    if (value == nullptr) throw std::invalid_argument("unexpected argument '" + arg + "'");
    if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
    *value = argv[++i];
  }
  if (options.config.empty()) throw std::invalid_argument("--config FILE is required");
  if (options.name.empty() || options.name.find('/') != std::string::npos) {
    throw std::invalid_argument("--name must be a node name without '/' (got '" + options.name +
                                "')");
  }
  return options;
}

namespace {

/// The parameters as driver_node loads them, from the file: unknown keys warned about, validated.
params::DriverParams loadCheckedParams(const std::string& path) {
  std::vector<std::string> unknown;
  params::DriverParams params = params::loadParamsFile(path, &unknown);
  for (const auto& key : unknown) {
    core::log(core::LogLevel::kWarn, "unknown parameter ~%s is ignored (a typo?)", key.c_str());
  }
  params.validate();
  return params;
}

/// Runs the core and its DDS front end until one of `stop_signals` arrives, then shuts down in
/// the node's order: no more input, the devices' last words, the ports closed.
void runUntilStopped(const params::DriverParams& params, const DdsDriverOptions& options,
                     const core::StopSignals& stop_signals) {
  // Before any thread starts, Cyclone DDS's included: they inherit it (core/scheduler_slice.h).
  core::requestSchedulerSlice(params.scheduler_slice_us);
  core::DriverCore core(
      params, core::SerialLink::StreamFactory{}, nullptr,
      [](const std::string& warning) { core::log(core::LogLevel::kWarn, "%s", warning.c_str()); });
  DdsNode node(params, nodeOptions(params.ros2, options.name, options.node_namespace), core);
  TrajectoryLoop trajectories(core.trajectories(), params.loop_rate);
  core.start();
  trajectories.start();
  node.start();
  core::log(core::LogLevel::kInfo, "%s; ROS 2 node %s on DDS domain %d",
            core.startupSummary().c_str(),
            dds::fullyQualifiedName(options.node_namespace, options.name).c_str(),
            node.participant().domainId());
  stop_signals.wait(std::chrono::hours(1));
  core::log(core::LogLevel::kInfo, "shutting down: stopping the wheels and the bus servos");
  node.shutdown();
  trajectories.shutdown();  // goals end before their joints' devices stop
  core.shutdown();
}

}  // namespace

int runDdsDriver(int argc, const char* const* argv) {
  const core::StopSignals stop_signals;  // before any thread starts: every thread inherits it
  DdsDriverOptions options;
  params::DriverParams params;
  try {
    bool help = false;
    options = parseDdsDriverArguments(argc, argv, &help);
    if (help) {
      std::cout << ddsDriverUsage();
      return 0;
    }
    params = loadCheckedParams(options.config);
  } catch (const std::exception& e) {  // ParameterError, a bad command line or file
    core::log(core::LogLevel::kError, "dds_driver: %s", e.what());
    std::cerr << ddsDriverUsage();
    return 2;
  }
  try {
    runUntilStopped(params, options, stop_signals);
  } catch (const params::ParameterError& e) {
    core::log(core::LogLevel::kError, "%s", e.what());
    return 2;
  } catch (const std::exception& e) {  // DDS refused the participant or a topic
    core::log(core::LogLevel::kError, "dds_driver: cannot join the ROS 2 graph: %s", e.what());
    return 1;
  }
  return 0;
}

}  // namespace serial_robot_driver::dds_front
