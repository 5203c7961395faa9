// follow_joint_trajectory (action) and joint_trajectory (topic) for one device's joints, with the
// semantics of ros_control's joint_trajectory_controller: goals checked whole before anything
// moves, one spline per joint sampled at the loop rate, path and goal tolerances, cancel holds the
// joints where they are, a new goal or message for the same joints preempts from the current
// desired state.
//
// Threading: the goal, cancel and topic callbacks and the loop timer run on the node's global
// callback queue and share the state below under mutex_. Callbacks only check and splice; the
// timer writes one frame per tick (a short write, as joint_commands does). updateActual() is
// called on the port's reader thread and only takes actual_mutex_, so a reader never waits for a
// tick. takeOver() runs another command's write under mutex_ so no trajectory frame can follow it.
#pragma once

#include <actionlib/server/action_server.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/trajectory/command.h"
#include "serial_robot_driver/trajectory/spline.h"
#include "serial_robot_driver/trajectory/tolerances.h"

namespace serial_robot_driver::ros_layer {

/// What a device gives the trajectory server: its joints and how to set their positions.
struct TrajectoryJoints {
  std::vector<trajectory::JointRange> joints;
  /// Writes one frame setting these joints (rad); returns an error text, empty when written.
  std::function<std::string(const std::vector<std::string>& names,
                            const std::vector<double>& positions)>
      write;
};

/// A ROS-free command from a JointTrajectory message (stamps are left to the caller).
trajectory::TrajectoryCommand toTrajectoryCommand(const trajectory_msgs::JointTrajectory& msg);

class TrajectoryServer {
 public:
  using Action = serial_robot_driver::FollowJointTrajectoryAction;
  using GoalHandle = actionlib::ServerGoalHandle<Action>;

  /// Advertises follow_joint_trajectory and joint_trajectory in `nh`'s namespace (started by
  /// start()).
  TrajectoryServer(ros::NodeHandle& nh, const DriverParams& params, TrajectoryJoints joints);
  ~TrajectoryServer();

  void start();
  /// Aborts every goal and stops the timer. Idempotent.
  void shutdown();

  /// The measured state of the joints (names as in TrajectoryJoints; an empty velocity: unknown).
  /// Any thread.
  void updateActual(const sensor_msgs::JointState& state);

  /// Another command (`source`, e.g. "joint_commands") for `names`: runs `write` under the lock
  /// and, when it wrote (returns true), stops the trajectories of those joints and aborts the
  /// goals that ran them, saying so.
  void takeOver(const std::vector<std::string>& names, const std::string& source,
                const std::function<bool()>& write);

  /// Aborts every goal and holds every joint where it is, with `reason` (the e-stop's hook).
  void stopAll(const std::string& reason);

 private:
  struct Track {
    trajectory::JointSpline spline;
    bool writing = false;  ///< the timer writes this joint (until its spline's end is written)
  };
  struct ActiveGoal {
    GoalHandle handle;
    std::vector<std::size_t> joints;
    std::vector<std::string> names;
    std::vector<trajectory::JointTolerance> path_tolerances;
    std::vector<trajectory::JointTolerance> goal_tolerances;
    double start_time = 0.0;
    double end_time = 0.0;
    double goal_time_tolerance = 0.0;
  };
  using Result = serial_robot_driver::FollowJointTrajectoryResult;

  void onGoal(GoalHandle handle);
  void onCancel(GoalHandle handle);
  void onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg);
  void onTick(const ros::TimerEvent& event);

  /// Checks `command` (starting at `start`, now `now`) against the joints and where they are;
  /// the indices of its joints in `check`. mutex_ held.
  trajectory::CommandCheck check(const trajectory::TrajectoryCommand& command, double start,
                                 double now);
  /// Ends the goals that drive any of `joints` (cancelled when `preempted`, else aborted with
  /// `code`), with `message`. mutex_ held.
  void endGoalsOn(const std::vector<std::size_t>& joints, bool preempted, int code,
                  const std::string& message);
  /// Splices the command into the joints' splines. mutex_ held.
  void apply(const trajectory::TrajectoryCommand& command, const std::vector<std::size_t>& joints,
             double start, double now);
  /// Holds `joints` where they are measured (desired where there is no measurement). mutex_ held.
  void hold(const std::vector<std::size_t>& joints, double now);
  /// Measured state of every joint and whether it is fresh enough to run a goal on; whether the
  /// velocities were measured in `velocity_known`.
  bool actualState(std::vector<trajectory::JointSample>* actual, double now,
                   bool* velocity_known = nullptr) const;
  /// Ends a goal when its tolerances say so; publishes its feedback otherwise. mutex_ held.
  bool superviseGoal(ActiveGoal& goal, double now, const std::vector<trajectory::JointSample>& actual,
                     bool actual_fresh, bool velocity_known);
  static Result result(int code, const std::string& message);

  const TrajectoryParams defaults_;
  const TrajectoryJoints joints_;
  const double loop_period_;
  ros::NodeHandle nh_;

  mutable std::mutex actual_mutex_;  // guards the measurement below
  std::vector<trajectory::JointSample> actual_;
  bool velocity_known_ = false;
  ros::Time actual_stamp_;  ///< zero: no measurement yet

  std::mutex mutex_;  // guards everything below
  std::vector<Track> tracks_;
  std::vector<ActiveGoal> goals_;
  bool running_ = false;
  actionlib::ActionServer<Action> action_server_;
  ros::Subscriber trajectory_sub_;
  ros::Timer timer_;
};

}  // namespace serial_robot_driver::ros_layer
