#include "serial_robot_driver/description/robot_description.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"

namespace serial_robot_driver::description {

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

void collectKeys(const YAML::Node& node, const std::string& prefix,
                 std::vector<std::string>* keys) {
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

bool YamlParamSource::has(const std::string& key) const { return find(*root_, key).IsDefined(); }

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

Mount mountOf(const Mounts& mounts, const std::string& name) {
  const auto it = mounts.find(name);
  return it == mounts.end() ? Mount{} : it->second;
}

std::vector<MountPoint> mountPoints() {
  std::vector<MountPoint> points;
  for (const DescriptionPart* part : registeredDescriptionParts()) {
    points.insert(points.end(), part->mounts.begin(), part->mounts.end());
  }
  return points;
}

std::string linkName(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

std::vector<ServoJoint> servoJoints(const DriverParams& params) {
  std::vector<ServoJoint> servos;
  for (const DescriptionPart* part : registeredDescriptionParts()) {
    if (!part->servo_joints) continue;
    const std::vector<ServoJoint> joints = part->servo_joints(params);
    servos.insert(servos.end(), joints.begin(), joints.end());
  }
  return servos;
}

namespace {

/// The servos: joints on top of the chassis, in a row across it, each turning a short arm about y.
void drawServoRow(const std::vector<ServoJoint>& servos, const Chassis& chassis, UrdfWriter& urdf) {
  const double arm_length = chassis.arm_length;
  for (std::size_t i = 0; i < servos.size(); ++i) {
    const ServoJoint& servo = servos[i];
    const std::string link = childLink(servo.name);
    const double y = chassis.width / 2.0 - (i + 0.5) * chassis.width / servos.size();
    urdf.link(link, servo.key,
              visual(box(0.02, 0.02, arm_length), "servo", numbers({0, 0, arm_length / 2.0})));
    std::ostringstream limit;
    limit << "    <axis xyz=\"0 1 0\"/>\n    <limit lower=\"" << numbers({servo.lower})
          << "\" upper=\"" << numbers({servo.upper}) << "\" velocity=\""
          << numbers({servo.velocity})
          << "\" effort=\"1.0\"/>\n";  // URDF requires an effort; nothing here enforces it
    urdf.joint(servo.name, servo.key, "revolute", chassis.root_link, link,
               numbers({chassis.length / 4.0, y, chassis.top}), "0 0 0", limit.str());
  }
}

}  // namespace

std::string makeRobotDescription(const DriverParams& params, const Mounts& mounts,
                                 const std::string& robot_name) {
  UrdfWriter urdf(robot_name);
  std::optional<Chassis> chassis;
  for (const DescriptionPart* part : registeredDescriptionParts()) {
    if (part->chassis && !chassis) chassis = part->chassis(params, urdf);
  }
  if (!chassis) throw std::logic_error("robot description: no device draws the chassis");
  for (const DescriptionPart* part : registeredDescriptionParts()) {
    if (part->fixed) part->fixed(params, *chassis, mounts, urdf);
  }
  drawServoRow(servoJoints(params), *chassis, urdf);
  return urdf.finish();
}

}  // namespace serial_robot_driver::description
