// robot_description: prints the URDF of the robot a driver parameter file configures, for
// `<param name="robot_description" command="$(find serial_robot_driver)/... CONFIG"/>`.
//   robot_description CONFIG.yaml [--imu-xyz "X Y Z"] [--imu-rpy "R P Y"] [--name NAME]
// The file is read with the driver's own defaults and checks (loadParams, validate()).
#include <cstring>
#include <iostream>
#include <sstream>

#include "serial_robot_driver/ros/robot_description.h"

namespace {

using serial_robot_driver::ros_layer::ImuMount;

constexpr const char* kUsage =
    "usage: robot_description CONFIG.yaml [--imu-xyz \"X Y Z\"] [--imu-rpy \"R P Y\"] [--name NAME]\n"
    "  prints the URDF of the robot CONFIG.yaml configures (driver_node's parameter file);\n"
    "  --imu-xyz (m) and --imu-rpy (rad) place imu_link on the base (default 0 0 0).\n";

bool parseTriple(const char* text, std::array<double, 3>* out) {
  std::istringstream in(text);
  for (double& v : *out) {
    if (!(in >> v)) return false;
  }
  std::string rest;
  return !(in >> rest);
}

}  // namespace

int main(int argc, char** argv) {
  namespace srd = serial_robot_driver::ros_layer;
  std::string config;
  std::string name = "serial_robot";
  ImuMount imu;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if ((arg == "--imu-xyz" || arg == "--imu-rpy") && has_value) {
      if (!parseTriple(argv[++i], arg == "--imu-xyz" ? &imu.xyz : &imu.rpy)) {
        std::cerr << "robot_description: " << arg << " takes three numbers, got '" << argv[i]
                  << "'\n";
        return 2;
      }
    } else if (arg == "--name" && has_value) {
      name = argv[++i];
    } else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (config.empty() && arg.rfind("--", 0) != 0) {
      config = arg;
    } else {
      std::cerr << "robot_description: unexpected argument '" << arg << "'\n" << kUsage;
      return 2;
    }
  }
  if (config.empty()) {
    std::cerr << kUsage;
    return 2;
  }
  try {
    const srd::YamlParamSource source(config);
    const srd::DriverParams params = srd::loadParams(source, nullptr);
    params.validate();
    std::cout << srd::makeRobotDescription(params, imu, name);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "robot_description: " << config << ": " << e.what() << "\n";
    return 1;
  }
}
