#include "serial_robot_driver/trajectory/joint_groups.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace serial_robot_driver::trajectory {

namespace {
constexpr double kMaxRotateIntervalMs = 65535.0;  // ROTATE's interval is a u16
}  // namespace

double steadyNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::optional<double> streamedHoldPosition(std::optional<double> last_written,
                                           std::optional<double> last_commanded,
                                           std::optional<double> fresh_measurement) {
  if (last_written) return last_written;
  if (last_commanded) return last_commanded;
  return fresh_measurement;
}

TrajectoryJoints bodyTrajectoryJoints(device::BodyController& controller) {
  TrajectoryJoints result;
  for (const device::BodyJoint& joint : controller.joints()) {
    const auto [low, high] = joint.calibration.reachableRadians();
    result.joints.push_back({joint.name, low, high});
  }
  result.write = [&controller](const std::vector<std::string>& names,
                               const std::vector<double>& positions,
                               std::optional<uint64_t> accepted) {
    const device::JointCommandResult sent = controller.sendJointCommand(names, positions, accepted);
    return sent.ok() && sent.out_of_range.empty() ? std::string() : sent.message();
  };
  result.generation = [&controller] { return controller.gate().generation(); };
  // Where a stop holds a joint the trajectories never wrote: the board's last command for it.
  result.last_commanded = [&controller](std::size_t index) {
    return controller.lastCommandedPosition(index);
  };
  return result;
}

const BusJoint* findBusJoint(const std::vector<BusJoint>& joints, uint8_t id) {
  const auto it = std::find_if(joints.begin(), joints.end(),
                               [id](const BusJoint& joint) { return joint.id == id; });
  return it == joints.end() ? nullptr : &*it;
}

double busStateTimeout(double state_rate) { return std::max(0.5, 3.0 / state_rate); }

TrajectoryJoints busTrajectoryJoints(const std::vector<BusJoint>& joints, QueueServoMove queue_move,
                                     double state_rate, StopServo stop_servo) {
  TrajectoryJoints result;
  for (const BusJoint& joint : joints) result.joints.push_back(joint.range());
  result.state_timeout = busStateTimeout(state_rate);
  if (stop_servo) {
    result.stop = [joints, stop_servo](std::size_t index) {
      return stop_servo(joints.at(index).id);
    };
  }
  result.move = [joints, queue_move](std::size_t index, double position, double duration) {
    const BusJoint& joint = joints.at(index);
    // A segment longer than ROTATE can say is given its longest interval; the next segment's
    // move, or the goal tolerance, catches up.
    const double interval_ms = std::clamp(std::round(duration * 1000.0), 0.0, kMaxRotateIntervalMs);
    return queue_move(joint.id, joint.toServoDegrees(position), static_cast<uint32_t>(interval_ms));
  };
  return result;
}

}  // namespace serial_robot_driver::trajectory
