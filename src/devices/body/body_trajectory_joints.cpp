#include "serial_robot_driver/devices/body/body_trajectory_joints.h"

namespace serial_robot_driver::devices::body {

TrajectoryJoints bodyTrajectoryJoints(devices::body::BodyController& controller) {
  TrajectoryJoints result;
  for (const devices::body::BodyJoint& joint : controller.joints()) {
    const auto [low, high] = joint.calibration.reachableRadians();
    result.joints.push_back({joint.name, low, high});
  }
  result.write = [&controller](const std::vector<std::string>& names,
                               const std::vector<double>& positions,
                               std::optional<uint64_t> accepted) {
    const devices::body::JointCommandResult sent =
        controller.sendJointCommand(names, positions, accepted);
    return sent.ok() && sent.out_of_range.empty() ? std::string() : sent.message();
  };
  result.generation = [&controller] { return controller.gate().generation(); };
  // Where a stop holds a joint the trajectories never wrote: the board's last command for it.
  result.last_commanded = [&controller](std::size_t index) {
    return controller.lastCommandedPosition(index);
  };
  return result;
}

}  // namespace serial_robot_driver::devices::body
