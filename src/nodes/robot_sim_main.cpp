// robot_sim: the simulated robot on pseudo-terminal(s). See `robot_sim --help` and
// serial_robot_driver/sim/robot_sim.h. Prints one line per pty, runs until SIGINT/SIGTERM, then
// prints a summary of its counters and exits 0.
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>

#include "serial_robot_driver/core/stop_signals.h"
#include "serial_robot_driver/sim/command_line.h"
#include "serial_robot_driver/sim/robot_sim.h"

namespace sim = serial_robot_driver::sim;

int main(int argc, char** argv) {
  sim::CommandLine command_line = sim::parseCommandLine(argc, argv);
  if (!command_line.error.empty()) {
    std::cerr << "robot_sim: " << command_line.error << "\n\n" << sim::usage();
    return 2;
  }
  if (command_line.help) {
    std::cout << sim::usage();
    return 0;
  }

  // Before any thread starts, so only the wait below sees them.
  const serial_robot_driver::core::StopSignals stop_signals;

  command_line.options.on_event = [](const std::string& text) {
    std::cout << text << std::endl;  // endl: flushed, a launcher may be reading line by line
  };
  sim::RobotSim robot(command_line.options);
  try {
    robot.start();
  } catch (const std::exception& error) {
    std::cerr << "robot_sim: " << error.what() << std::endl;
    return 1;
  }
  for (const sim::SimPort& port : robot.ports()) {
    std::string devices;
    for (const std::string& name : port.devices) devices += (devices.empty() ? "" : ",") + name;
    std::cout << "robot_sim: " << devices << " on " << port.slave_path
              << (port.link.empty() ? "" : " (link " + port.link + ")") << std::endl;
  }

  stop_signals.wait(std::chrono::milliseconds(200));
  robot.stop();
  std::cout << "robot_sim: stopped\n" << sim::formatStats(robot.stats()) << std::flush;
  return 0;
}
