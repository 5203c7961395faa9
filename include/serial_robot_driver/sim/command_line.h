// The robot_sim command line: one table of flags (command_line.cpp) yields both the parser and
// the --help text.
#pragma once

#include <string>

#include "serial_robot_driver/sim/sim_options.h"

namespace serial_robot_driver::sim {

/// Result of parsing the robot_sim command line.
struct CommandLine {
  SimOptions options;
  bool help = false;
  std::string error;  ///< non-empty: print usage on stderr and exit 2
};

/// Parses robot_sim flags. Arguments containing ":=" (roslaunch remappings, __name:=x) are ignored.
CommandLine parseCommandLine(int argc, const char* const* argv);
/// The --help text.
std::string usage();

}  // namespace serial_robot_driver::sim
