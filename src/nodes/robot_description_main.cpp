// robot_description: prints the URDF of the robot a driver parameter file configures, for
// `<param name="robot_description" command="$(find serial_robot_driver)/... CONFIG"/>`.
//   robot_description CONFIG.yaml [--imu-xyz "X Y Z"] [--imu-rpy "R P Y"] [--name NAME]
// The file is read with the driver's own defaults and checks (loadParams, validate()).
#include <cstring>
#include <iostream>
#include <sstream>

#include "serial_robot_driver/ros/robot_description.h"

namespace {

namespace srd = serial_robot_driver::ros_layer;

/// The usage text, with the mounts the devices' parts take (description::MountPoint).
std::string usage() {
  std::string options, mounts;
  for (const auto& point : srd::mountPoints()) {
    options += " [--" + point.name + "-xyz \"X Y Z\"] [--" + point.name + "-rpy \"R P Y\"]";
    mounts += "  --" + point.name + "-xyz (m) and --" + point.name + "-rpy (rad) place " +
              point.what + " on the base (default 0 0 0).\n";
  }
  return "usage: robot_description CONFIG.yaml" + options + " [--name NAME]\n" +
         "  prints the URDF of the robot CONFIG.yaml configures (driver_node's parameter file);\n" +
         mounts;
}

bool parseTriple(const char* text, std::array<double, 3>* out) {
  std::istringstream in(text);
  for (double& v : *out) {
    if (!(in >> v)) return false;
  }
  std::string rest;
  return !(in >> rest);
}

/// The coordinates `arg` sets when it is --<mount>-xyz or --<mount>-rpy of a known mount, else
/// null.
std::array<double, 3>* mountArgument(const std::string& arg, srd::Mounts& mounts) {
  for (const auto& point : srd::mountPoints()) {
    if (arg == "--" + point.name + "-xyz") return &mounts[point.name].xyz;
    if (arg == "--" + point.name + "-rpy") return &mounts[point.name].rpy;
  }
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  std::string config;
  std::string name = "serial_robot";
  srd::Mounts mounts;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (std::array<double, 3>* coordinates = has_value ? mountArgument(arg, mounts) : nullptr) {
      if (!parseTriple(argv[++i], coordinates)) {
        std::cerr << "robot_description: " << arg << " takes three numbers, got '" << argv[i]
                  << "'\n";
        return 2;
      }
    } else if (arg == "--name" && has_value) {
      name = argv[++i];
    } else if (arg == "-h" || arg == "--help") {
      std::cout << usage();
      return 0;
    } else if (config.empty() && arg.rfind("--", 0) != 0) {
      config = arg;
    } else {
      std::cerr << "robot_description: unexpected argument '" << arg << "'\n" << usage();
      return 2;
    }
  }
  if (config.empty()) {
    std::cerr << usage();
    return 2;
  }
  try {
    const srd::YamlParamSource source(config);
    const srd::DriverParams params = srd::loadParams(source, nullptr);
    params.validate();
    std::cout << srd::makeRobotDescription(params, mounts, name);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "robot_description: " << config << ": " << e.what() << "\n";
    return 1;
  }
}
