// The servo bus in the robot description: one servo joint per bus servo used as a joint
// (~servo_bus/joint_ids ...), limited to what a single-turn servo reaches.
#include <cmath>

#include "serial_robot_driver/description/robot_description.h"
#include "serial_robot_driver/devices/servo_bus/bus_trajectory_joints.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::servo_bus {

namespace {

std::vector<description::ServoJoint> servoJoints(const description::DriverParams& params) {
  std::vector<description::ServoJoint> servos;
  if (!params.section(kServoBusSection).enabled) return servos;
  constexpr double kMaxBusServoSpeedDps = 750.0;  // servo/move's velocity limit
  for (const trajectory::BusJoint& joint :
       makeBusJoints(params.section(kServoBusSection))) {
    const trajectory::JointRange range = joint.range();
    servos.push_back({joint.name, "servo_bus/joint_names", range.min_position, range.max_position,
                      kMaxBusServoSpeedDps * M_PI / 180.0});
  }
  return servos;
}

}  // namespace

extern const description::DescriptionPart kDescription{.servo_joints = servoJoints};

}  // namespace serial_robot_driver::devices::servo_bus
