// follow_joint_trajectory (action) and joint_trajectory (topic) for the node's joints: messages
// converted to and from the node's ROS-free trajectory::TrajectoryExecutor (trajectory/executor.h,
// the one the devices attach to), which decides everything (acceptance, sampling, tolerances,
// preemption, stops), and a steady timer that ticks it at the loop rate.
//
// Time: the executor runs on the steady clock (trajectory::steadyNow()); a goal's header.stamp
// (ROS time) becomes a steady start once, on receipt, so a step of the ROS or wall clock changes
// nothing on the wire.
//
// Threading: the goal, cancel and topic callbacks and the loop timer run on the node's global
// callback queue; the executor's own lock orders them with the devices' calls (updateActual() on
// a port's reader thread or the bus worker, takeOver() from their command callbacks).
#pragma once

#include <actionlib/server/action_server.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/ros/guarded_action_server.h"
#include "serial_robot_driver/trajectory/executor.h"
#include "serial_robot_driver/trajectory/message_time.h"

namespace serial_robot_driver::ros_layer {

using trajectory::TrajectoryJoints;

/// A ROS stamp as the core's trajectories take it (trajectory/message_time.h: steadyStart(),
/// never ros::Duration, which throws beyond +-68 years).
trajectory::MessageStamp toMessageStamp(const ros::Time& stamp);

/// A ROS-free command from a JointTrajectory message (stamps are left to the caller).
trajectory::TrajectoryCommand toTrajectoryCommand(const trajectory_msgs::JointTrajectory& msg);

class TrajectoryServer {
 public:
  using Action = serial_robot_driver::FollowJointTrajectoryAction;
  using GoalHandle = actionlib::ServerGoalHandle<Action>;

  /// Advertises follow_joint_trajectory and joint_trajectory in `nh`'s namespace (started by
  /// start()) for `executor`, which outlives this object; what it refuses is counted in
  /// `refusals` (the core's, DriverCore::inputRefusals(), which outlives this object too).
  TrajectoryServer(ros::NodeHandle& nh, const DriverParams& params,
                   trajectory::TrajectoryExecutor& executor, core::InputRefusals& refusals);
  ~TrajectoryServer();
  /// The executor's warnings (a goal's stop, a late sample) for the ROS log.
  static trajectory::TrajectoryExecutor::Warn logWarning();

  /// Starts the executor, the action server, the topic and the loop timer.
  void start();
  /// Aborts every goal and stops the timer. Idempotent.
  void shutdown();

 private:
  /// onGoal() guarded: an error rejects the goal (or aborts it, once accepted).
  void onGoalGuarded(GoalHandle handle);
  void onGoal(GoalHandle handle);
  void onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg);
  /// The steady start of a message stamped `stamp`; nothing: at once.
  std::optional<double> startOf(const ros::Time& stamp) const;

  core::InputRefusals& input_refusals_;  // before the callbacks that count into it
  trajectory::TrajectoryExecutor& executor_;
  const double loop_period_;
  ros::NodeHandle nh_;
  GuardedActionServer<Action> action_server_;
  ros::Subscriber trajectory_sub_;
  ros::SteadyTimer timer_;
};

}  // namespace serial_robot_driver::ros_layer
