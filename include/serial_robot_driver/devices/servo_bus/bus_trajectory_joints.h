// The UART bus servos used as joints (~servo_bus/joint_ids, joint_names, joint_zero_deg,
// joint_directions) as the trajectory executor sees them (trajectory/joint_groups.h): one move
// per segment. Also each polled angle as a joint measurement. ROS-free.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/trajectory/bus_joint.h"
#include "serial_robot_driver/trajectory/joint_groups.h"

namespace serial_robot_driver::devices::servo_bus {

using trajectory::BusJoint;
using trajectory::TrajectoryJoints;

/// The bus servos named as joints, from validated parameters (empty zero / direction lists: 0 / 1).
std::vector<BusJoint> makeBusJoints(const ServoBusParams& params);

/// The joint of bus servo `id`, if it is one.
const BusJoint* findBusJoint(const std::vector<BusJoint>& joints, uint8_t id);

/// A measured joint: its name and position (rad).
struct JointPosition {
  std::string name;
  double position = 0.0;
};

/// One polled angle as a joint measurement: the joint's name and position (rad) where `id` is a
/// joint, else servo_<id> and the servo's angle in rad.
JointPosition busJointPosition(const std::vector<BusJoint>& joints, uint8_t id, double angle_deg);

/// Queues a move of servo `id` to `angle_deg` (single-turn) in `interval_ms`; must not block.
/// Returns an error text, empty when queued.
using QueueServoMove =
    std::function<std::string(uint8_t id, double angle_deg, uint32_t interval_ms)>;

/// Stops servo `id` where it is (a SPIN stop, no position); must not block. Returns an error
/// text, empty when queued.
using StopServo = std::function<std::string(uint8_t id)>;

/// How long a bus joint may go without a poll answer before its goal aborts: three poll periods at
/// `state_rate` (Hz), at least 0.5 s.
double busStateTimeout(double state_rate);

/// The bus joints for the trajectory executor: one ROTATE per segment, at its start, with the
/// segment's remaining duration as interval; a stop holds a joint with `stop_servo` (may be
/// empty: nothing is sent). Its state_timeout is busStateTimeout(state_rate).
TrajectoryJoints busTrajectoryJoints(const std::vector<BusJoint>& joints, QueueServoMove queue_move,
                                     double state_rate, StopServo stop_servo = {});

}  // namespace serial_robot_driver::devices::servo_bus
