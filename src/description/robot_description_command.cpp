#include "serial_robot_driver/description/robot_description_command.h"

#include <array>
#include <exception>
#include <sstream>

namespace serial_robot_driver::description {

namespace {

bool parseTriple(const std::string& text, std::array<double, 3>* out) {
  std::istringstream in(text);
  for (double& v : *out) {
    if (!(in >> v)) return false;
  }
  std::string rest;
  return !(in >> rest);
}

/// The coordinates `arg` sets when it is --<mount>-xyz or --<mount>-rpy of a known mount, else
/// null.
std::array<double, 3>* mountArgument(const std::string& arg, Mounts& mounts) {
  for (const auto& point : mountPoints()) {
    if (arg == "--" + point.name + "-xyz") return &mounts[point.name].xyz;
    if (arg == "--" + point.name + "-rpy") return &mounts[point.name].rpy;
  }
  return nullptr;
}

}  // namespace

std::string descriptionUsage() {
  std::string options, mounts;
  for (const auto& point : mountPoints()) {
    options += " [--" + point.name + "-xyz \"X Y Z\"] [--" + point.name + "-rpy \"R P Y\"]";
    mounts += "  --" + point.name + "-xyz (m) and --" + point.name + "-rpy (rad) place " +
              point.what + " on the base (default 0 0 0).\n";
  }
  return "usage: robot_description CONFIG.yaml" + options + " [--name NAME]\n" +
         "  prints the URDF of the robot CONFIG.yaml configures (driver_node's parameter file);\n" +
         mounts;
}

ParsedDescriptionArguments parseDescriptionArguments(const std::vector<std::string>& args) {
  ParsedDescriptionArguments parsed;
  DescriptionRequest request;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    const bool has_value = i + 1 < args.size();
    if (std::array<double, 3>* coordinates =
            has_value ? mountArgument(arg, request.mounts) : nullptr) {
      if (!parseTriple(args[++i], coordinates)) {
        parsed.error =
            "robot_description: " + arg + " takes three numbers, got '" + args[i] + "'\n";
        return parsed;
      }
    } else if (arg == "--name" && has_value) {
      request.name = args[++i];
    } else if (arg == "-h" || arg == "--help") {
      parsed.help = true;
      return parsed;
    } else if (request.config.empty() && arg.rfind("--", 0) != 0) {
      request.config = arg;
    } else {
      parsed.error = "robot_description: unexpected argument '" + arg + "'\n" + descriptionUsage();
      return parsed;
    }
  }
  if (request.config.empty()) {
    parsed.error = descriptionUsage();
  } else {
    parsed.request = request;
  }
  return parsed;
}

int runRobotDescription(const std::vector<std::string>& args, std::ostream& out,
                        std::ostream& err) {
  const ParsedDescriptionArguments parsed = parseDescriptionArguments(args);
  if (parsed.help) {
    out << descriptionUsage();
    return 0;
  }
  if (!parsed.request) {
    err << parsed.error;
    return 2;
  }
  const DescriptionRequest& request = *parsed.request;
  try {
    const YamlParamSource source(request.config);
    const DriverParams params = params::loadParams(source, nullptr);
    params.validate();
    out << makeRobotDescription(params, request.mounts, request.name);
    return 0;
  } catch (const std::exception& e) {
    err << "robot_description: " << request.config << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace serial_robot_driver::description
