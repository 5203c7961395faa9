#include "serial_robot_driver/ros/robot_description.h"

#include <cmath>

#include "serial_robot_driver/ros/conversions.h"
#include "serial_robot_driver/ros/trajectory_bus_joints.h"

namespace serial_robot_driver::ros_layer {

std::vector<description::ServoJoint> servoJoints(const DriverParams& params) {
  std::vector<description::ServoJoint> servos;
  if (params.section(params::kBodySection).enabled) {
    const std::vector<device::BodyJoint> joints =
        makeBodyJoints(params.section(params::kBodySection));
    for (const device::BodyJoint& joint : joints) {
      const auto [lower, upper] = joint.calibration.reachableRadians();
      // The board's speed unit is not known (body/velocity_scale); one turn per second.
      servos.push_back({joint.name, "body/joint_names", lower, upper, 2.0 * M_PI});
    }
  }
  if (params.section(params::kServoBusSection).enabled) {
    constexpr double kMaxBusServoSpeedDps = 750.0;  // servo/move's velocity limit
    for (const trajectory::BusJoint& joint :
         makeBusJoints(params.section(params::kServoBusSection))) {
      const trajectory::JointRange range = joint.range();
      servos.push_back({joint.name, "servo_bus/joint_names", range.min_position,
                        range.max_position, kMaxBusServoSpeedDps * M_PI / 180.0});
    }
  }
  return servos;
}

std::string makeRobotDescription(const DriverParams& params, const ImuMount& imu,
                                 const std::string& robot_name) {
  return description::makeRobotDescription(params, servoJoints(params), imu, robot_name);
}

}  // namespace serial_robot_driver::ros_layer
