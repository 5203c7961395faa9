#include "serial_robot_driver/ros/robot_description.h"
#include "serial_robot_driver/ros/trajectory_bus_joints.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

// --- the parameter file ----------------------------------------------------------------------

namespace {

/// The node at a "a/b/c" path below `root`; an undefined node when any step is missing.
YAML::Node find(const YAML::Node& root, const std::string& key) {
  // Nodes are references: reset() moves `node` along without writing into the document.
  YAML::Node node;
  node.reset(root);
  std::size_t start = 0;
  while (start <= key.size()) {
    const std::size_t slash = std::min(key.find('/', start), key.size());
    const std::string step = key.substr(start, slash - start);
    if (!node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& map = node;
    const YAML::Node next = map[step];  // const lookup: inserts nothing
    if (!next.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    node.reset(next);
    start = slash + 1;
  }
  return node;
}

template <typename T>
bool readScalar(const YAML::Node& node, T* out) {
  if (!node.IsScalar()) return false;
  *out = node.as<T>();
  return true;
}

template <typename T>
bool readList(const YAML::Node& node, std::vector<T>* out) {
  if (!node.IsSequence()) return false;
  std::vector<T> values;
  for (const auto& item : node) {
    T value;
    if (!readScalar(item, &value)) return false;
    values.push_back(value);
  }
  *out = std::move(values);
  return true;
}

void collectKeys(const YAML::Node& node, const std::string& prefix, std::vector<std::string>* keys) {
  for (const auto& entry : node) {
    const std::string key = prefix + entry.first.as<std::string>();
    if (entry.second.IsMap()) {
      collectKeys(entry.second, key + "/", keys);
    } else {
      keys->push_back(key);
    }
  }
}

}  // namespace

YamlParamSource::YamlParamSource(const std::string& path) {
  try {
    root_ = std::make_unique<YAML::Node>(YAML::LoadFile(path));
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("cannot read the parameter file " + path + ": " + e.what());
  }
  // An empty file is an empty set of parameters, as for rosparam.
  if (!root_->IsMap() && !root_->IsNull()) {
    throw std::runtime_error("the parameter file " + path + " is not a YAML mapping of parameters");
  }
}

YamlParamSource::~YamlParamSource() = default;

bool YamlParamSource::has(const std::string& key) const {
  return find(*root_, key).IsDefined();
}

bool YamlParamSource::get(const std::string& key, ParamValue* value) const {
  const YAML::Node node = find(*root_, key);
  try {
    return std::visit(
        [&node](auto& typed) {
          using T = std::decay_t<decltype(typed)>;
          if constexpr (std::is_same_v<T, std::vector<int>> ||
                        std::is_same_v<T, std::vector<double>> ||
                        std::is_same_v<T, std::vector<std::string>>) {
            return readList(node, &typed);
          } else {
            return readScalar(node, &typed);
          }
        },
        *value);
  } catch (const YAML::Exception&) {
    return false;  // e.g. "0.5" where an integer belongs
  }
}

std::vector<std::string> YamlParamSource::keys() const {
  std::vector<std::string> keys;
  if (root_->IsMap()) collectKeys(*root_, "", &keys);
  return keys;
}

// --- the URDF --------------------------------------------------------------------------------

namespace {

std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string numbers(std::initializer_list<double> values) {
  std::ostringstream text;
  text << std::setprecision(9);
  const char* separator = "";
  for (double v : values) {
    text << separator << (v == 0.0 ? 0.0 : v);  // no "-0"
    separator = " ";
  }
  return text.str();
}

/// A wheel's or servo's link: the joint name without a trailing "_joint", plus "_link".
std::string childLink(const std::string& joint) {
  const std::string suffix = "_joint";
  const bool has_suffix =
      joint.size() > suffix.size() && joint.compare(joint.size() - suffix.size(), suffix.size(), suffix) == 0;
  return (has_suffix ? joint.substr(0, joint.size() - suffix.size()) : joint) + "_link";
}

/// A revolute servo joint with its reachable range.
struct ServoJoint {
  std::string name;
  std::string key;  ///< the parameter that names it, for errors
  double lower, upper;
  double velocity;  ///< rad/s limit
};

class UrdfWriter {
 public:
  explicit UrdfWriter(const std::string& robot_name) {
    out_ << "<?xml version=\"1.0\"?>\n"
         << "<!-- Generated by serial_robot_driver's robot_description from the driver's parameter "
            "file. Do not edit: change the parameters. -->\n"
         << "<robot name=\"" << escaped(robot_name) << "\">\n"
         << "  <material name=\"chassis\"><color rgba=\"0.75 0.75 0.78 1\"/></material>\n"
         << "  <material name=\"wheel\"><color rgba=\"0.15 0.15 0.15 1\"/></material>\n"
         << "  <material name=\"servo\"><color rgba=\"0.95 0.55 0.1 1\"/></material>\n"
         << "  <material name=\"imu\"><color rgba=\"0.1 0.4 0.9 1\"/></material>\n";
  }

  void link(const std::string& name, const std::string& key, const std::string& visuals) {
    if (!links_.insert(name).second) {
      throw ParameterError(key, "gives the link '" + name + "', which another link already has");
    }
    out_ << "  <link name=\"" << escaped(name) << "\">\n" << visuals << "  </link>\n";
  }

  void joint(const std::string& name, const std::string& key, const std::string& type,
             const std::string& parent, const std::string& child, const std::string& xyz,
             const std::string& rpy, const std::string& extra) {
    if (!joints_.insert(name).second) {
      throw ParameterError(key, "names the joint '" + name + "', which another joint already has");
    }
    out_ << "  <joint name=\"" << escaped(name) << "\" type=\"" << type << "\">\n"
         << "    <parent link=\"" << escaped(parent) << "\"/>\n"
         << "    <child link=\"" << escaped(child) << "\"/>\n"
         << "    <origin xyz=\"" << xyz << "\" rpy=\"" << rpy << "\"/>\n"
         << extra << "  </joint>\n";
  }

  std::string finish() {
    out_ << "</robot>\n";
    return out_.str();
  }

 private:
  std::ostringstream out_;
  std::set<std::string> links_, joints_;
};

std::string visual(const std::string& geometry, const std::string& material,
                   const std::string& xyz = "0 0 0", const std::string& rpy = "0 0 0") {
  return "    <visual>\n      <origin xyz=\"" + xyz + "\" rpy=\"" + rpy + "\"/>\n      <geometry>" +
         geometry + "</geometry>\n      <material name=\"" + material + "\"/>\n    </visual>\n";
}

std::string box(double x, double y, double z) { return "<box size=\"" + numbers({x, y, z}) + "\"/>"; }

std::string cylinder(double radius, double length) {
  return "<cylinder radius=\"" + numbers({radius}) + "\" length=\"" + numbers({length}) + "\"/>";
}

std::string sphere(double radius) { return "<sphere radius=\"" + numbers({radius}) + "\"/>"; }

}  // namespace

std::string linkName(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

std::string makeRobotDescription(const DriverParams& params, const ImuMount& imu,
                                 const std::string& robot_name) {
  // Simple shapes sized from the wheel geometry: base_link on the ground between the wheels
  // (REP-105), the axle at the wheel radius, a box chassis and a rear caster ball.
  const BaseParams& base = params.base;
  const double radius = base.wheel_diameter / 2.0;
  const double wheel_width = std::min(0.25 * base.wheel_diameter, 0.3 * base.wheel_separation);
  const double chassis_length = std::max(1.2 * base.wheel_diameter, 0.8 * base.wheel_separation);
  const double chassis_width = base.wheel_separation - 1.2 * wheel_width;
  const double chassis_height = radius;
  const double chassis_top = radius + chassis_height / 2.0;
  const std::string base_link = linkName(base.base_frame);

  UrdfWriter urdf(robot_name);
  urdf.link(base_link, "base/base_frame",
            visual(box(chassis_length, chassis_width, chassis_height), "chassis",
                   numbers({0, 0, radius})) +
                visual(sphere(radius / 2.0), "wheel",
                       numbers({-(chassis_length / 2.0 - radius / 2.0), 0, radius / 2.0})));

  const auto wheel = [&](const std::string& joint, const std::string& key, double side) {
    const std::string link = childLink(joint);
    // The cylinder's axis is its z: turned onto y, the axis the wheel spins about.
    urdf.link(link, key, visual(cylinder(radius, wheel_width), "wheel", "0 0 0",
                                numbers({M_PI / 2.0, 0, 0})));
    urdf.joint(joint, key, "continuous", base_link, link,
               numbers({0, side * base.wheel_separation / 2.0, radius}), "0 0 0",
               "    <axis xyz=\"0 1 0\"/>\n");
  };
  wheel(base.left_wheel_joint, "base/left_wheel_joint", 1.0);
  wheel(base.right_wheel_joint, "base/right_wheel_joint", -1.0);

  const std::string imu_link = linkName(params.imu.frame_id);
  urdf.link(imu_link, "imu/frame_id", visual(box(0.03, 0.03, 0.01), "imu"));
  urdf.joint(imu_link + "_joint", "imu/frame_id", "fixed", base_link, imu_link,
             numbers({imu.xyz[0], imu.xyz[1], imu.xyz[2]}),
             numbers({imu.rpy[0], imu.rpy[1], imu.rpy[2]}), "");

  // The servos: joints on top of the chassis, in a row across it, each turning a short arm
  // about y. Their limits are what the servo reaches, through the joint's zero and direction.
  std::vector<ServoJoint> servos;
  if (params.body.enabled) {
    const std::vector<device::BodyJoint> joints = makeBodyJoints(params.body);
    for (const device::BodyJoint& joint : joints) {
      const auto [lower, upper] = joint.calibration.reachableRadians();
      // The board's speed unit is not known (body/velocity_scale); one turn per second.
      servos.push_back({joint.name, "body/joint_names", lower, upper, 2.0 * M_PI});
    }
  }
  if (params.servo_bus.enabled) {
    constexpr double kMaxBusServoSpeedDps = 750.0;  // servo/move's velocity limit
    for (const trajectory::BusJoint& joint : makeBusJoints(params.servo_bus)) {
      const trajectory::JointRange range = joint.range();
      servos.push_back({joint.name, "servo_bus/joint_names", range.min_position,
                        range.max_position, kMaxBusServoSpeedDps * M_PI / 180.0});
    }
  }
  const double arm_length = std::max(0.05, 0.8 * radius);
  for (std::size_t i = 0; i < servos.size(); ++i) {
    const ServoJoint& servo = servos[i];
    const std::string link = childLink(servo.name);
    const double y = chassis_width / 2.0 - (i + 0.5) * chassis_width / servos.size();
    urdf.link(link, servo.key,
              visual(box(0.02, 0.02, arm_length), "servo", numbers({0, 0, arm_length / 2.0})));
    std::ostringstream limit;
    limit << "    <axis xyz=\"0 1 0\"/>\n    <limit lower=\"" << numbers({servo.lower})
          << "\" upper=\"" << numbers({servo.upper}) << "\" velocity=\"" << numbers({servo.velocity})
          << "\" effort=\"1.0\"/>\n";  // URDF requires an effort; nothing here enforces it
    urdf.joint(servo.name, servo.key, "revolute", base_link, link,
               numbers({chassis_length / 4.0, y, chassis_top}), "0 0 0", limit.str());
  }
  return urdf.finish();
}

}  // namespace serial_robot_driver::ros_layer
