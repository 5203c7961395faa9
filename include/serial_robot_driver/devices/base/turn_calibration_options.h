// calibrate_base's command line (docs/calibration.md, "On the robot"): ROS-free, so that the
// options and their ranges are unit-tested without a master.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace serial_robot_driver::devices::base {

/// calibrate_base's exit statuses besides 0 (a result) and 128 + signal (stopped by a signal).
constexpr int kCalibrationExitRefused = 1;  ///< refused or aborted
constexpr int kCalibrationExitUsage = 2;    ///< a bad option

/// The text of --help.
extern const char* const kCalibrateBaseUsage;

struct CalibrationOptions {
  double rate = 1.0;                 ///< rad/s of the turns
  double angle = 6.283185307179586;  ///< rad each turn goes, commanded
  double distance = 0.0;             ///< m of the straight run afterwards; 0: none
  double speed = 0.2;                ///< m/s of the straight run
  std::optional<double> measured;    ///< m the straight run really went, instead of asking
  std::string node;                  ///< the driver node; empty: the one publishing wheel_command
  double settle = 0.5;               ///< s of rest before and after each motion
};

struct ParsedCalibrationOptions {
  std::optional<CalibrationOptions> options;  ///< unset when help or on a bad option
  bool help = false;                          ///< --help or -h: print kCalibrateBaseUsage
  std::string error;                          ///< why an option is bad ("" otherwise)
};

/// Why the tool stops for a signal ("interrupted (SIGINT)", "terminated"); the exit status is
/// 128 + the signal's number.
std::string stopSignalMessage(int signal_number);

/// Why no driver to calibrate was found on `topic` (wheel_command): the signal that ended the
/// search, ROS shutting down (`ros_ok` false), or none publishing it.
std::string noCalibrationDriverText(int stop_signal, bool ros_ok, const std::string& topic);

/// Parses the arguments after the program's name, once ros::init removed the ROS remappings.
ParsedCalibrationOptions parseCalibrationOptions(const std::vector<std::string>& args);

}  // namespace serial_robot_driver::devices::base
