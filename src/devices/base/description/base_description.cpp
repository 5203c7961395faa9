// The base in the robot description: the chassis (base_link) and its two wheels, sized from the
// wheel geometry.
#include <algorithm>
#include <cmath>

#include "serial_robot_driver/description/robot_description.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::base {

namespace {

using description::box;
using description::Chassis;
using description::numbers;
using description::UrdfWriter;
using description::visual;

/// One wheel (a cylinder turned onto y, the axis it spins about) on a continuous joint.
void drawWheel(UrdfWriter& urdf, const std::string& base_link, const std::string& joint,
               const std::string& key, double side, double radius, double width,
               double separation) {
  const std::string link = description::childLink(joint);
  urdf.link(
      link, key,
      visual(description::cylinder(radius, width), "wheel", "0 0 0", numbers({M_PI / 2.0, 0, 0})));
  urdf.joint(joint, key, "continuous", base_link, link,
             numbers({0, side * separation / 2.0, radius}), "0 0 0", "    <axis xyz=\"0 1 0\"/>\n");
}

Chassis drawChassis(const description::DriverParams& params, UrdfWriter& urdf) {
  // Simple shapes sized from the wheel geometry: base_link on the ground between the wheels
  // (REP-105), the axle at the wheel radius, a box chassis and a rear caster ball.
  const BaseParams& section = params.section(kBaseSection);
  const kinematics::DiffDriveGeometry& wheels = section.controller.geometry;
  const double radius = wheels.wheel_diameter / 2.0;
  const double wheel_width = std::min(0.25 * wheels.wheel_diameter, 0.3 * wheels.wheel_separation);
  Chassis chassis;
  chassis.root_link = description::linkName(section.base_frame);
  chassis.length = std::max(1.2 * wheels.wheel_diameter, 0.8 * wheels.wheel_separation);
  chassis.width = wheels.wheel_separation - 1.2 * wheel_width;
  const double chassis_height = radius;
  chassis.top = radius + chassis_height / 2.0;
  chassis.arm_length = std::max(0.05, 0.8 * radius);

  urdf.link(chassis.root_link, "base/base_frame",
            visual(box(chassis.length, chassis.width, chassis_height), "chassis",
                   numbers({0, 0, radius})) +
                visual(description::sphere(radius / 2.0), "wheel",
                       numbers({-(chassis.length / 2.0 - radius / 2.0), 0, radius / 2.0})));
  drawWheel(urdf, chassis.root_link, section.left_wheel_joint, "base/left_wheel_joint", 1.0, radius,
            wheel_width, wheels.wheel_separation);
  drawWheel(urdf, chassis.root_link, section.right_wheel_joint, "base/right_wheel_joint", -1.0,
            radius, wheel_width, wheels.wheel_separation);
  return chassis;
}

}  // namespace

extern const description::DescriptionPart kDescription{.chassis = drawChassis};

}  // namespace serial_robot_driver::devices::base
