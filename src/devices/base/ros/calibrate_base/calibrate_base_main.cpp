// calibrate_base: turns the running robot in place both ways, compares the IMU's yaw with the turn
// its wheel frames commanded and prints the effective wheel separation (docs/calibration.md).
// A client of the node's topics, never a node service: the user sees progress, Ctrl-C stops it,
// it ties up none of the node's threads, and if it is killed hard the node's own
// ~base/cmd_vel_timeout stops the base. The run itself (sequencing, aborts, the stop on every way
// out, the report) is the core's devices/base/turn_calibration_run; this file finds the driver,
// spins the run with the topics wired to it (calibrate_base_client.cpp) and reads typed input.
#include <ros/ros.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <string>

#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/base/ros/calibrate_base_client.h"
#include "serial_robot_driver/devices/base/turn_calibration_run.h"
#include "serial_robot_driver/ros/driver_params.h"

namespace {

using namespace serial_robot_driver::devices::base;
using namespace serial_robot_driver::core;
using serial_robot_driver::devices::base::ros::CalibrationTopics;

std::atomic<int> g_signal{0};
void onSignal(int signal_number) { g_signal = signal_number; }

/// Steps the run to its end with what arrived; its exit status.
int spinRun(TurnCalibrationRun& run) {
  CalibrationTopics topics(run);
  // A ROS error mid-run fails the run, which still stops the base: it steps on regardless.
  auto guarded = [&run](auto&& call) {
    try {
      call();
    } catch (const std::exception& error) {
      run.fail(error.what());
    }
  };
  while (true) {
    guarded([] { ::ros::spinOnce(); });
    const CalibrationStep step =
        run.step({::ros::WallTime::now().toSec(), ::ros::Time::now().toSec(), g_signal.exchange(0),
                  ::ros::ok(), topics.commandSubscribed()});
    printCalibrationLines(step.lines, std::cout, std::cerr);
    if (step.command) guarded([&] { topics.command(*step.command); });
    if (step.finished) return step.exit_status;
    if (step.wants_measured_distance) {
      double measured = 0;
      // A signal interrupts the read (no SA_RESTART); the next step sees it.
      const bool typed = static_cast<bool>(std::cin >> measured);
      run.setMeasuredDistance(typed ? std::optional<double>(measured) : std::nullopt);
      continue;
    }
    ::ros::WallDuration(step.next_step_in).sleep();
  }
}

}  // namespace

int main(int argc, char** argv) {
  // Our own SIGINT/SIGTERM: the base is stopped before the tool exits, not after roscpp's.
  ::ros::init(argc, argv, "calibrate_base",
              ::ros::init_options::NoSigintHandler | ::ros::init_options::AnonymousName);
  const ParsedCalibrationOptions parsed =
      parseCalibrationOptions(std::vector<std::string>(argv + 1, argv + argc));
  if (parsed.help) {
    std::cout << kCalibrateBaseUsage;
    return 0;
  }
  if (!parsed.options) {
    std::cerr << parsed.error << "\n";
    return kCalibrationExitUsage;
  }
  // Without SA_RESTART, so that a signal also ends a wait for typed input.
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  ::ros::start();

  std::string why;
  const auto node = serial_robot_driver::devices::base::ros::findCalibrationDriver(
      parsed.options->node, g_signal, &why);
  if (!node) {
    std::cerr << "calibrate_base: " << why << std::endl;
    return g_signal != 0 ? 128 + g_signal : kCalibrationExitRefused;
  }
  BaseConfig base;
  try {  // the node's parameters read as the node reads them (its defaults for keys left out)
    base = serial_robot_driver::ros_layer::loadParams(::ros::NodeHandle(*node), nullptr)
               .section(serial_robot_driver::devices::base::kBaseSection)
               .controller;
  } catch (const std::exception& error) {
    std::cerr << "calibrate_base: cannot read the parameters of " << *node << ": " << error.what()
              << std::endl;
    return kCalibrationExitRefused;
  }
  TurnCalibrationRun run(*parsed.options, *node, ::ros::names::resolve("imu/data"), base);
  const int status = spinRun(run);
  ::ros::shutdown();
  return status;
}
