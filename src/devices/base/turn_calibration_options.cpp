#include "serial_robot_driver/devices/base/turn_calibration_options.h"

#include <csignal>
#include <cstdlib>
#include <sstream>

namespace serial_robot_driver::devices::base {

const char* const kCalibrateBaseUsage =
    R"(usage: rosrun serial_robot_driver calibrate_base [options]

Turns the robot in place counter-clockwise, then clockwise, compares the IMU's yaw (imu/data)
with the turn the wheel frames commanded (wheel_command) and prints the effective
wheel_separation. Nothing is written to the node or the config: the tool prints the value, the
command to try it now and the line to keep it. Needs telemetry and the e-stop released; Ctrl-C
stops the base and exits. Run it in the driver's namespace (ROS_NAMESPACE=... for a fleet).

  --rate RAD_S      turning rate (default 1.0)
  --angle RAD       how far each turn goes, commanded (default 6.283: a full turn)
  --distance M      also drive this far straight ahead (commanded) and ask for the distance
                    really travelled: prints the effective wheel_diameter (default 0: no)
  --speed M_S       speed of the straight run (default 0.2)
  --measured M      the measured distance of the straight run, instead of asking for it
  --node NAME       the driver node (default: the node publishing wheel_command)
  --settle S        rest before and after each motion (default 0.5)
  --help            this text
)";

std::string stopSignalMessage(int signal_number) {
  return signal_number == SIGINT ? "interrupted (SIGINT)" : "terminated";
}

std::string noCalibrationDriverText(int stop_signal, bool ros_ok, const std::string& topic) {
  if (stop_signal != 0) return stopSignalMessage(stop_signal);
  if (!ros_ok) return "ROS shut down";
  return "no driver publishes " + topic +
         ": start it first (roslaunch serial_robot_driver sim.launch), or run the tool in its "
         "namespace (ROS_NAMESPACE=...)";
}

ParsedCalibrationOptions parseCalibrationOptions(const std::vector<std::string>& args) {
  ParsedCalibrationOptions parsed;
  CalibrationOptions options;
  // The value after args[i], within low..high; sets parsed.error when it is missing or bad.
  auto number = [&](std::size_t& i, double low, double high, double* out) {
    const std::string& name = args[i];
    if (i + 1 >= args.size()) {
      parsed.error = name + " needs a value";
      return false;
    }
    const std::string& text = args[++i];
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (*end != '\0' || !(value >= low && value <= high)) {
      std::ostringstream why;
      why << name << " must be a number in " << low << ".." << high << ", not " << text;
      parsed.error = why.str();
      return false;
    }
    *out = value;
    return true;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    double measured = 0;
    bool ok = true;
    if (arg == "--help" || arg == "-h") {
      parsed.help = true;
      return parsed;
    } else if (arg == "--rate") {
      ok = number(i, 0.05, 5.0, &options.rate);
    } else if (arg == "--angle") {
      ok = number(i, 0.5, 40.0, &options.angle);
    } else if (arg == "--distance") {
      ok = number(i, 0.0, 20.0, &options.distance);
    } else if (arg == "--speed") {
      ok = number(i, 0.02, 2.0, &options.speed);
    } else if (arg == "--measured") {
      ok = number(i, 0.0, 40.0, &measured);
      options.measured = measured;
    } else if (arg == "--settle") {
      ok = number(i, 0.1, 5.0, &options.settle);
    } else if (arg == "--node" && i + 1 < args.size()) {
      options.node = args[++i];
    } else {
      parsed.error = "unknown option " + arg + " (--help lists them)";
      ok = false;
    }
    if (!ok) return parsed;
  }
  parsed.options = options;
  return parsed;
}

}  // namespace serial_robot_driver::devices::base
