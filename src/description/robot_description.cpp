#include "serial_robot_driver/description/robot_description.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"

namespace serial_robot_driver::description {

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
