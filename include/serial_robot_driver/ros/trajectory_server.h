// follow_joint_trajectory (action) and joint_trajectory (topic) for the node's joints, with the
// semantics of ros_control's joint_trajectory_controller: goals checked whole before anything
// moves, one spline per joint sampled at the loop rate, path and goal tolerances, cancel holds the
// joints where they are, a new goal or message for the same joints preempts from the current
// desired state.
//
// Stops (an empty trajectory, a cancel, an abort, stopAll) hold each joint where the node last
// commanded it: a streamed joint at the position last written for it (by the server, else by the
// device's own last command, else where it is measured when that is fresh); a per-segment joint
// by its `stop` hook, with nothing positional sent. A joint neither commanded nor measured is left
// alone, and the answer names it.
//
// Time: sampling, tolerances, goal timing and staleness run on the steady clock (seconds of
// std::chrono::steady_clock, see steadyNow()); a goal's header.stamp (ROS time) becomes a steady
// start once, on receipt, so a step of the ROS or wall clock changes nothing on the wire.
//
// Threading: the goal, cancel and topic callbacks and the loop timer run on the node's global
// callback queue and share the state below under mutex_. Callbacks only check and splice; the
// timer writes one frame per tick for streamed joints (a short write, as joint_commands does) and
// hands segment moves to the bus's own queue. updateActual() is called on a port's reader thread
// or the bus worker and only takes actual_mutex_, so neither ever waits for a tick. takeOver()
// runs another command's write under mutex_ so no trajectory frame can follow it.
#pragma once

#include <actionlib/server/action_server.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryAction.h"
#include "serial_robot_driver/device/e_stop.h"
#include "serial_robot_driver/ros/driver_params.h"
#include "serial_robot_driver/trajectory/command.h"
#include "serial_robot_driver/trajectory/spline.h"
#include "serial_robot_driver/trajectory/tolerances.h"

namespace serial_robot_driver::ros_layer {

/// What a device gives the trajectory server: its joints and how to set their positions, either
/// streamed (`write` every loop tick: the body) or one move per segment (`move`: bus servos).
struct TrajectoryJoints {
  std::vector<trajectory::JointRange> joints;
  /// A goal aborts when one of its joints has had no measurement for this long (s).
  double state_timeout = 0.5;
  /// Writes one frame setting these joints (rad); returns an error text, empty when written.
  std::function<std::string(const std::vector<std::string>& names,
                            const std::vector<double>& positions)>
      write;
  /// Instead of `write`: moves joint `index` (into `joints`) to `position` (rad) in `duration` s;
  /// must not block (queue the frame). Returns an error text, empty when queued.
  std::function<std::string(std::size_t index, double position, double duration)> move;
  /// Streamed joints: the position (rad) the device last commanded joint `index`, by whatever
  /// command; nothing when it never did. May be empty.
  std::function<std::optional<double>(std::size_t index)> last_commanded;
  /// Per-segment joints: stops joint `index` where it is, with no position (how a stop holds it);
  /// must not block. Returns an error text, empty when queued. May be empty (nothing is sent).
  std::function<std::string(std::size_t index)> stop;
};

/// The trajectory clock: seconds of std::chrono::steady_clock.
double steadyNow();
/// The steady time of a ROS `stamp` (zero: `steady_now`), given the two clocks read together.
double steadyStart(const ros::Time& stamp, double steady_now, const ros::Time& ros_now);
/// Where a stop holds a streamed joint: the position the server last wrote, else the device's last
/// command, else the measurement when it is fresh (pass nothing when stale); nothing: leave it
/// alone (no default, no old end point).
std::optional<double> streamedHoldPosition(std::optional<double> last_written,
                                           std::optional<double> last_commanded,
                                           std::optional<double> fresh_measurement);

/// A ROS-free command from a JointTrajectory message (stamps are left to the caller).
trajectory::TrajectoryCommand toTrajectoryCommand(const trajectory_msgs::JointTrajectory& msg);

class TrajectoryServer {
 public:
  using Action = serial_robot_driver::FollowJointTrajectoryAction;
  using GoalHandle = actionlib::ServerGoalHandle<Action>;

  /// Advertises follow_joint_trajectory and joint_trajectory in `nh`'s namespace (started by
  /// start()).
  TrajectoryServer(ros::NodeHandle& nh, const DriverParams& params,
                   std::vector<TrajectoryJoints> groups);
  ~TrajectoryServer();
  /// New defaults (~trajectory: tolerances, max_velocity) for the goals and messages accepted
  /// from now on; a running goal goes on with the tolerances it was accepted with.
  void retune(const TrajectoryParams& defaults);
  /// A new measurement timeout (s) for the joints `names` (others ignored), for the goals running
  /// and to come (e.g. after ~servo_bus/state_rate changed).
  void setStateTimeout(const std::vector<std::string>& names, double seconds);

  void start();
  /// Aborts every goal and stops the timer. Idempotent.
  void shutdown();

  /// The measured state of some joints (names as in TrajectoryJoints; other names are ignored;
  /// an empty velocity: unknown). Any thread.
  void updateActual(const sensor_msgs::JointState& state);

  /// Another command (`source`, e.g. "joint_commands") for `names`: runs `write` under the lock
  /// and, when it wrote (returns true), stops the trajectories of those joints and aborts the
  /// goals that ran them, saying so.
  void takeOver(const std::vector<std::string>& names, const std::string& source,
                const std::function<bool()>& write);

  /// Aborts every goal and holds every joint it drives where it was last commanded, with `reason`
  /// (the e-stop's hook).
  void stopAll(const std::string& reason);
  /// The node's e-stop (before start()): engaging it calls stopAll(); while it holds, goals are
  /// rejected and joint_trajectory messages ignored, both counted.
  void attachEStop(device::EStop& e_stop);

 private:
  struct Track {
    std::size_t group = 0;  ///< index into groups_
    std::size_t local = 0;  ///< index into that group's joints
    double state_timeout = 0.5;
    trajectory::JointSpline spline;
    bool writing = false;       ///< the timer writes this joint (until its spline's end is written)
    double sent_segment = 0.0;  ///< per-segment joints: start of the segment whose move went out
    /// Streamed joints: the position the server last wrote (a write that succeeded); cleared when
    /// another command takes the joint over.
    std::optional<double> last_written;
    bool moved = false;  ///< per-segment joints: the server has queued a move of this joint
  };
  struct Measured {
    trajectory::JointSample sample;
    bool velocity_known = false;
    std::optional<double> received;  ///< steady time of receipt; nothing: never measured
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
  void onTick(const ros::SteadyTimerEvent& event);

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
  /// Holds `joints` where they were last commanded (see the top of this file); returns the text
  /// naming the joints left alone ("" when none). mutex_ held.
  std::string hold(const std::vector<std::size_t>& joints, double now);
  /// The latest measurement of every joint.
  std::vector<Measured> measured() const;
  /// The first of `joints` whose measurement is older than its timeout at `now`, or -1.
  long staleJoint(const std::vector<Measured>& measured, const std::vector<std::size_t>& joints,
                  double now) const;
  /// Writes (streamed groups) or queues (per-segment groups) what the tracks ask for. mutex_ held.
  void writeTracks(double now);
  /// Ends a goal when its tolerances say so; publishes its feedback otherwise. mutex_ held.
  bool superviseGoal(ActiveGoal& goal, double now, const std::vector<Measured>& measured);
  static Result result(int code, const std::string& message);

  TrajectoryParams defaults_;  // guarded by mutex_; retune() changes it
  const std::vector<TrajectoryJoints> groups_;
  std::vector<trajectory::JointRange> ranges_;          ///< every joint, in track order
  std::unordered_map<std::string, std::size_t> index_;  ///< joint name -> track
  const double loop_period_;
  ros::NodeHandle nh_;

  mutable std::mutex actual_mutex_;  // guards the measurements below
  std::vector<Measured> actual_;

  std::mutex mutex_;  // guards everything below
  std::vector<Track> tracks_;
  std::vector<ActiveGoal> goals_;
  bool running_ = false;
  device::EStop* e_stop_ = nullptr;
  actionlib::ActionServer<Action> action_server_;
  ros::Subscriber trajectory_sub_;
  ros::SteadyTimer timer_;
};

}  // namespace serial_robot_driver::ros_layer
