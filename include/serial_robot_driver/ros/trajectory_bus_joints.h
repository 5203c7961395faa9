// The seam between the trajectory server and the UART bus servos used as joints
// (~servo_bus/joint_ids, joint_names, joint_zero_deg, joint_directions). The servo bus needs to
// offer only two things: a way to queue "servo id to this angle in this many ms" without blocking,
// and to report each polled angle (busJointState() turns one into a measurement).
#pragma once

#include <ros/time.h>
#include <sensor_msgs/JointState.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/trajectory_server.h"
#include "serial_robot_driver/trajectory/bus_joint.h"

namespace serial_robot_driver::ros_layer {

/// The bus servos named as joints, from validated parameters (empty zero / direction lists: 0 / 1).
std::vector<trajectory::BusJoint> makeBusJoints(const ServoBusParams& params);

/// The joint of bus servo `id`, if it is one.
const trajectory::BusJoint* findBusJoint(const std::vector<trajectory::BusJoint>& joints,
                                         uint8_t id);

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

/// The bus joints for the trajectory server: one ROTATE per segment, at its start, with the
/// segment's remaining duration as interval; a stop holds a joint with `stop_servo` (may be
/// empty: nothing is sent). Its state_timeout is busStateTimeout(state_rate).
TrajectoryJoints busTrajectoryJoints(const std::vector<trajectory::BusJoint>& joints,
                                     QueueServoMove queue_move, double state_rate,
                                     StopServo stop_servo = {});

/// One polled angle as a joint measurement: the joint's name and position (rad) where `id` is a
/// joint, else servo_<id> and the servo's angle in rad.
sensor_msgs::JointState busJointState(const std::vector<trajectory::BusJoint>& joints, uint8_t id,
                                      double angle_deg, const ros::Time& stamp);

}  // namespace serial_robot_driver::ros_layer
