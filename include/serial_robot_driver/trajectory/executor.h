// Trajectory execution, ROS-free, with the semantics of ros_control's joint_trajectory_controller:
// goals checked whole before anything moves, one spline per joint sampled each tick, path and goal
// tolerances, cancel holds the joints where they are, a new goal or message for the same joints
// preempts from the current desired state. The ROS layer (ros/trajectory_server.h) only converts
// messages and calls in here.
//
// Stops (an empty trajectory, a cancel, an abort, stopAll) hold each joint where the node last
// commanded it: a streamed joint at the position last written for it (by the executor, else by the
// device's own last command, else where it is measured when that is fresh); a per-segment joint
// by its `stop` hook, with nothing positional sent. A joint neither commanded nor measured is left
// alone, and the answer names it.
//
// Time: sampling, tolerances, goal timing and staleness run on the injected clock (the steady
// clock in the driver, see steadyNow(); tests step it by hand). A goal's start is given on that
// clock, so a step of the ROS or wall clock changes nothing on the wire.
//
// Threading: every call may come from any thread; they share the state below under mutex_ and call
// the goal callbacks with it held. tick() writes one frame per streamed group (a short write) and
// hands segment moves to the bus's own queue. updateActual() only takes actual_mutex_, so a port's
// reader never waits for a tick. takeOver() runs another command's write under mutex_ so no
// trajectory frame can follow it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/trajectory/bus_joint.h"
#include "serial_robot_driver/trajectory/command.h"
#include "serial_robot_driver/trajectory/goal.h"
#include "serial_robot_driver/trajectory/joint_groups.h"
#include "serial_robot_driver/trajectory/spline.h"
#include "serial_robot_driver/trajectory/tolerances.h"

namespace serial_robot_driver::trajectory {

class TrajectoryExecutor {
 public:
  using Clock = std::function<double()>;
  /// A warning for the log (the driver's ROS_WARN); some are throttled to one a second per kind.
  using Warn = std::function<void(const std::string&)>;

  TrajectoryExecutor(std::vector<TrajectoryJoints> groups, const GoalDefaults& defaults,
                     Clock clock = steadyNow, Warn warn = {});

  /// The executor's clock now.
  double now() const { return clock_(); }
  /// New defaults for the goals and messages accepted from now on; a running goal goes on with
  /// the tolerances it was accepted with.
  void retune(const GoalDefaults& defaults);
  /// A new measurement timeout (s) for the joints `names` (others ignored), for the goals running
  /// and to come (e.g. after ~servo_bus/state_rate changed).
  void setStateTimeout(const std::vector<std::string>& names, double seconds);

  /// Until start() goals are rejected and messages ignored. False when it had started already.
  bool start();
  /// Aborts every goal; then as before start(). Idempotent.
  void shutdown();

  /// The measured state of some joints (other names are ignored; velocities empty or shorter:
  /// unknown). Any thread; freshness is the time of this call.
  void updateActual(const std::vector<std::string>& names, const std::vector<double>& positions,
                    const std::vector<double>& velocities);
  /// tracksOf()'s answer for a name that is none of the executor's joints.
  static constexpr std::size_t kNoTrack = static_cast<std::size_t>(-1);
  /// Each name's track (kNoTrack: not a joint of this executor), for a caller whose joints never
  /// change to look them up once rather than by name with every measurement. Any thread.
  std::vector<std::size_t> tracksOf(const std::vector<std::string>& names) const;
  /// updateActual() of the joints tracks[i] (from tracksOf()), measured positions[i].
  void updateActual(const std::vector<std::size_t>& tracks, const std::vector<double>& positions,
                    const std::vector<double>& velocities);

  /// What became of a goal or message: accepted, or why not (the goal's callbacks say it too).
  enum class Submission { kAccepted, kNotRunning, kEStopped, kInvalid };

  /// A follow_joint_trajectory goal: rejected, or accepted (preempting the goals on its joints)
  /// and run by tick(); an empty trajectory holds its joints and succeeds at once. A start further
  /// ahead than max_start_delay is invalid; a start in the past is effectiveStart()'s.
  Submission submitGoal(const Goal& goal, GoalCallbacks callbacks);
  /// Cancels the running goal `id` (holding its joints); nothing when it is over.
  void cancelGoal(const std::string& id);
  /// A joint_trajectory message: as a goal nobody follows; one that fails its check is ignored.
  Submission submitTrajectory(const TrajectoryCommand& command, std::optional<double> start_time);

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
  void attachEStop(core::EStop& e_stop);

  /// One loop tick: supervises the goals (ending them, else giving feedback), then writes or
  /// queues what the splines ask for.
  void tick();
  /// What calls tick() (the node's loop timer): switched on (true) when there is work from now on
  /// (a goal, a trajectory, a hold to write), off (false) after the tick that left none, so an
  /// idle executor wakes no thread. Called under the executor's lock: it may only start or stop
  /// a timer. Unset, tick() is the caller's to call.
  void setTicker(std::function<void(bool on)> ticker);

  /// Why trajectories may be moving joints now: a goal in progress or joints still being written
  /// or moved; "" when none. Any thread (a sensor calibration asks it once per frame).
  std::string motionInForce();
  /// Whether motionInForce() would name something, without building its text. Any thread.
  bool inMotion();

 private:
  /// Requires mutex_: joint `j` is being written or is in a goal.
  bool jointInMotionLocked(std::size_t j) const;
  struct Track {
    std::size_t group = 0;  ///< index into groups_
    std::size_t local = 0;  ///< index into that group's joints
    double state_timeout = 0.5;
    JointSpline spline;
    double sent_segment = 0.0;  ///< per-segment joints: start of the segment whose move went out
    /// Streamed joints: the position last written (a write that succeeded); cleared when another
    /// command takes the joint over.
    std::optional<double> last_written;
    bool moved = false;  ///< per-segment joints: a move of this joint was queued
    /// The group's e-stop generation when what the track runs was accepted (or held): an e-stop
    /// since voids it (TrajectoryJoints::generation).
    std::optional<uint64_t> accepted;
  };
  /// Each group's e-stop generation now (unset where the group has none).
  using Generations = std::vector<std::optional<uint64_t>>;
  struct Measured {
    JointSample sample;
    bool velocity_known = false;
    std::optional<double> received;  ///< clock time of receipt; nothing: never measured
  };
  /// The warnings throttled to one a second, each kind on its own.
  enum ThrottledWarning { kTrajectoryError, kMessageRefused, kMessageInvalid, kThrottledKinds };

  /// Checks `command` (starting at `start`, now `now`) against the joints and where they are;
  /// the indices of its joints in `check`. mutex_ held (so are all below).
  CommandCheck check(const TrajectoryCommand& command, double start, double now);
  /// Splices the command, accepted under `accepted`, into the joints' splines.
  void apply(const TrajectoryCommand& command, const std::vector<std::size_t>& joints, double start,
             double now, const Generations& accepted);
  /// The groups' generations now (no lock needed: the groups are fixed).
  Generations generations() const;
  /// Whether an e-stop engaged since track `j`'s command was accepted.
  bool voided(std::size_t j) const;
  /// Stops `joints` (their commands were voided by an e-stop) and aborts their goals.
  void dropVoided(const std::vector<std::size_t>& joints, double now);
  /// Holds `joints` where they were last commanded (see the top of this file); returns the text
  /// naming the joints left alone ("" when none).
  std::string hold(const std::vector<std::size_t>& joints, double now);
  /// The latest measurement of every joint (takes actual_mutex_).
  std::vector<Measured> measured() const;
  /// The first of `joints` whose measurement is older than its timeout at `now`, or -1.
  long staleJoint(const std::vector<Measured>& measured, const std::vector<std::size_t>& joints,
                  double now) const;
  /// Writes (streamed groups) or queues (per-segment groups) what the tracks ask for.
  void writeTracks(double now);
  /// Ends a goal when its tolerances say so (true); gives its feedback otherwise.
  bool superviseGoal(ActiveGoal& goal, double now, const std::vector<Measured>& measured);
  /// Aborts the goal (holding its joints) when a joint's state is older than its state_timeout.
  bool abortIfTelemetryLost(ActiveGoal& goal, double now, const std::vector<Measured>& actual);
  /// Where the goal's joints should be and are (an unmeasured velocity as desired), as feedback.
  void sampleAndReport(const ActiveGoal& goal, double now, const std::vector<Measured>& actual,
                       std::vector<JointSample>* desired, std::vector<JointSample>* measured);
  /// The path tolerances until the end time, then the goal's: true when the goal is over.
  bool judgeTolerances(ActiveGoal& goal, double now, const std::vector<JointSample>& desired,
                       const std::vector<JointSample>& measured);
  void warn(const std::string& text) const;
  /// A goal, or a joint still to be written or moved (mutex_ held).
  bool busyLocked() const;
  /// Switches the ticker (mutex_ held); nothing once shut down.
  void setTickingLocked(bool on);
  void warnThrottled(ThrottledWarning kind, const std::string& text, double now);

  const std::vector<TrajectoryJoints> groups_;
  std::vector<JointRange> ranges_;                      ///< every joint, in track order
  std::unordered_map<std::string, std::size_t> index_;  ///< joint name -> track (never changes)
  const Clock clock_;
  const Warn warn_;
  std::function<void(bool)> ticker_;

  mutable std::mutex actual_mutex_;  // guards the measurements below
  std::vector<Measured> actual_;

  std::mutex mutex_;  // guards everything below
  GoalDefaults defaults_;
  std::vector<Track> tracks_;
  /// Per track: tick() writes this joint (until its spline's end is written). Kept apart from the
  /// tracks so that the motion question asked once per telemetry frame reads one cache line, not
  /// one Track each.
  std::vector<uint8_t> writing_;
  std::vector<ActiveGoal> goals_;
  bool running_ = false;
  bool ticking_ = false;  ///< the ticker is on
  core::EStop* e_stop_ = nullptr;
  std::array<std::optional<double>, kThrottledKinds> last_warned_;
};

}  // namespace serial_robot_driver::trajectory
