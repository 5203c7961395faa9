#include "serial_robot_driver/ros/trajectory_server.h"

#include <algorithm>
#include <cmath>

namespace serial_robot_driver::ros_layer {

namespace {

/// A goal whose joints have not been measured for this long is aborted: the driver can no longer
/// tell whether they follow.
constexpr double kTelemetryTimeout = 0.5;  // s

using trajectory::CommandError;
using trajectory::JointSample;

int resultCode(CommandError error) {
  using R = serial_robot_driver::FollowJointTrajectoryResult;
  switch (error) {
    case CommandError::kNone:
      return R::SUCCESSFUL;
    case CommandError::kInvalidJoints:
      return R::INVALID_JOINTS;
    case CommandError::kInvalidGoal:
      return R::INVALID_GOAL;
    case CommandError::kOldTimestamp:
      return R::OLD_HEADER_TIMESTAMP;
  }
  return R::INVALID_GOAL;
}

std::vector<trajectory::NamedTolerance> fromMsg(
    const std::vector<serial_robot_driver::JointTolerance>& list) {
  std::vector<trajectory::NamedTolerance> result;
  for (const auto& entry : list) result.push_back({entry.name, entry.position, entry.velocity});
  return result;
}

bool overlaps(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) {
  return std::any_of(a.begin(), a.end(),
                     [&](std::size_t j) { return std::find(b.begin(), b.end(), j) != b.end(); });
}

}  // namespace

trajectory::TrajectoryCommand toTrajectoryCommand(const trajectory_msgs::JointTrajectory& msg) {
  trajectory::TrajectoryCommand command;
  command.joint_names = msg.joint_names;
  for (const auto& point : msg.points) {
    command.points.push_back({point.time_from_start.toSec(), point.positions, point.velocities,
                              point.accelerations});
  }
  return command;
}

TrajectoryServer::TrajectoryServer(ros::NodeHandle& nh, const DriverParams& params,
                                   TrajectoryJoints joints)
    : defaults_(params.trajectory),
      joints_(std::move(joints)),
      loop_period_(1.0 / params.loop_rate),
      nh_(nh),
      actual_(joints_.joints.size()),
      tracks_(joints_.joints.size()),
      action_server_(nh, "follow_joint_trajectory",
                     [this](GoalHandle handle) { onGoal(handle); },
                     [this](GoalHandle handle) { onCancel(handle); }, false) {}

TrajectoryServer::~TrajectoryServer() { shutdown(); }

void TrajectoryServer::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_) return;
  running_ = true;
  action_server_.start();
  // tcpNoDelay: a trajectory must not wait in Nagle's buffer.
  trajectory_sub_ = nh_.subscribe("joint_trajectory", 10, &TrajectoryServer::onTrajectory, this,
                                  ros::TransportHints().tcpNoDelay());
  timer_ = nh_.createTimer(ros::Duration(loop_period_), &TrajectoryServer::onTick, this);
}

void TrajectoryServer::shutdown() {
  timer_.stop();
  trajectory_sub_.shutdown();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return;
  running_ = false;
  for (ActiveGoal& goal : goals_) {
    goal.handle.setAborted(result(Result::INVALID_GOAL, "the driver is shutting down"),
                           "the driver is shutting down");
  }
  goals_.clear();
}

void TrajectoryServer::updateActual(const sensor_msgs::JointState& state) {
  std::lock_guard<std::mutex> lock(actual_mutex_);
  const std::size_t count = std::min(state.position.size(), actual_.size());
  velocity_known_ = state.velocity.size() >= count;
  // Telemetry lists the joints in the order TrajectoryJoints has them.
  for (std::size_t j = 0; j < count; ++j) {
    actual_[j].position = state.position[j];
    actual_[j].velocity = velocity_known_ ? state.velocity[j] : 0.0;
  }
  actual_stamp_ = state.header.stamp.isZero() ? ros::Time::now() : state.header.stamp;
}

bool TrajectoryServer::actualState(std::vector<JointSample>* actual, double now,
                                   bool* velocity_known) const {
  std::lock_guard<std::mutex> lock(actual_mutex_);
  *actual = actual_;
  if (velocity_known) *velocity_known = velocity_known_;
  return !actual_stamp_.isZero() && now - actual_stamp_.toSec() <= kTelemetryTimeout;
}

TrajectoryServer::Result TrajectoryServer::result(int code, const std::string& message) {
  Result result;
  result.error_code = code;
  result.error_string = message;
  return result;
}

trajectory::CommandCheck TrajectoryServer::check(const trajectory::TrajectoryCommand& command,
                                                 double start, double now) {
  trajectory::CommandCheck result =
      trajectory::validate(command, joints_.joints, defaults_.max_velocity, start - now);
  if (!result.ok()) return result;
  std::vector<JointSample> actual;
  if (!actualState(&actual, now) && !command.points.empty()) {
    result.error = CommandError::kInvalidGoal;
    result.message = "no recent state of the joints (is telemetry arriving?): cannot start from "
                     "where they are";
    return result;
  }
  if (defaults_.max_velocity > 0.0) {
    // The bridge starts from the desired state where a trajectory runs, else from the measurement.
    std::vector<double> current;
    for (std::size_t j : result.joint_indices) {
      current.push_back(tracks_[j].writing ? tracks_[j].spline.sample(now).position
                                           : actual[j].position);
    }
    result = trajectory::validate(command, joints_.joints, defaults_.max_velocity, start - now,
                                  current);
  }
  return result;
}

void TrajectoryServer::endGoalsOn(const std::vector<std::size_t>& joints, bool preempted, int code,
                                  const std::string& message) {
  for (auto it = goals_.begin(); it != goals_.end();) {
    if (!overlaps(it->joints, joints)) {
      ++it;
      continue;
    }
    if (preempted) {
      it->handle.setCanceled(result(Result::SUCCESSFUL, message), message);
    } else {
      it->handle.setAborted(result(code, message), message);
    }
    it = goals_.erase(it);
  }
}

void TrajectoryServer::apply(const trajectory::TrajectoryCommand& command,
                             const std::vector<std::size_t>& joints, double start, double now) {
  std::vector<JointSample> actual;
  actualState(&actual, now);
  for (std::size_t column = 0; column < joints.size(); ++column) {
    Track& track = tracks_[joints[column]];
    // A joint nobody drives starts from where it is; a driven one from where it is meant to be.
    if (!track.writing) track.spline = trajectory::JointSpline(actual[joints[column]].position);
    track.spline.splice(std::max(start, now), trajectory::waypointsFor(command, column, start, now));
    track.writing = true;
  }
}

void TrajectoryServer::hold(const std::vector<std::size_t>& joints, double now) {
  std::vector<JointSample> actual;
  const bool measured = actualState(&actual, now);
  for (std::size_t j : joints) {
    const double position = measured ? actual[j].position : tracks_[j].spline.sample(now).position;
    tracks_[j].spline = trajectory::JointSpline(position);
    tracks_[j].writing = true;  // written once, then the servo keeps it
  }
}

void TrajectoryServer::onGoal(GoalHandle handle) {
  const auto goal = handle.getGoal();
  const trajectory::TrajectoryCommand command = toTrajectoryCommand(goal->trajectory);
  const double now = ros::Time::now().toSec();
  const double start =
      goal->trajectory.header.stamp.isZero() ? now : goal->trajectory.header.stamp.toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) {
    handle.setRejected(result(Result::INVALID_GOAL, "the driver is not running"),
                       "the driver is not running");
    return;
  }
  const trajectory::CommandCheck checked = check(command, start, now);
  if (!checked.ok()) {
    ROS_WARN("follow_joint_trajectory: goal rejected: %s", checked.message.c_str());
    handle.setRejected(result(resultCode(checked.error), checked.message), checked.message);
    return;
  }
  handle.setAccepted();
  endGoalsOn(checked.joint_indices, true, Result::SUCCESSFUL, "preempted by a new goal");
  if (command.points.empty()) {
    // joint_trajectory_controller's "stop": hold where they are, and that is done at once.
    hold(checked.joint_indices, now);
    handle.setSucceeded(result(Result::SUCCESSFUL, ""), "stopped where they are");
    return;
  }
  apply(command, checked.joint_indices, start, now);

  ActiveGoal active;
  active.handle = handle;
  active.joints = checked.joint_indices;
  active.names = command.joint_names;
  const trajectory::JointTolerance path_defaults{defaults_.path_tolerance, 0.0};
  const trajectory::JointTolerance goal_defaults{defaults_.goal_tolerance, 0.0};
  active.path_tolerances =
      trajectory::resolveTolerances(active.names, path_defaults, fromMsg(goal->path_tolerance));
  active.goal_tolerances =
      trajectory::resolveTolerances(active.names, goal_defaults, fromMsg(goal->goal_tolerance));
  active.start_time = start;
  active.end_time = start + command.points.back().time_from_start;
  active.goal_time_tolerance = goal->goal_time_tolerance.isZero()
                                   ? defaults_.goal_time_tolerance
                                   : std::max(0.0, goal->goal_time_tolerance.toSec());
  goals_.push_back(std::move(active));
}

void TrajectoryServer::onCancel(GoalHandle handle) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = std::find_if(goals_.begin(), goals_.end(),
                         [&](const ActiveGoal& goal) { return goal.handle == handle; });
  if (it == goals_.end()) return;  // already over
  hold(it->joints, ros::Time::now().toSec());
  it->handle.setCanceled(result(Result::SUCCESSFUL, "cancelled: holding where they are"),
                         "cancelled: holding where they are");
  goals_.erase(it);
}

void TrajectoryServer::onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
  const trajectory::TrajectoryCommand command = toTrajectoryCommand(*msg);
  const double now = ros::Time::now().toSec();
  const double start = msg->header.stamp.isZero() ? now : msg->header.stamp.toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return;
  const trajectory::CommandCheck checked = check(command, start, now);
  if (!checked.ok()) {
    ROS_WARN("joint_trajectory: message ignored, nothing moves: %s", checked.message.c_str());
    return;
  }
  endGoalsOn(checked.joint_indices, true, Result::SUCCESSFUL,
             "preempted by a joint_trajectory message");
  if (command.points.empty()) {
    hold(checked.joint_indices, now);
  } else {
    apply(command, checked.joint_indices, start, now);
  }
}

void TrajectoryServer::takeOver(const std::vector<std::string>& names, const std::string& source,
                                const std::function<bool()>& write) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!write()) return;
  std::vector<std::size_t> taken;
  for (const std::string& name : names) {
    for (std::size_t j = 0; j < joints_.joints.size(); ++j) {
      if (joints_.joints[j].name != name || !tracks_[j].writing) continue;
      tracks_[j].writing = false;
      taken.push_back(j);
    }
  }
  if (taken.empty()) return;
  const std::string message = "joint '" + joints_.joints[taken.front()].name + "' taken over by " +
                              source + ": trajectory stopped";
  ROS_WARN("%s", message.c_str());
  endGoalsOn(taken, false, Result::INVALID_GOAL, message);
}

void TrajectoryServer::stopAll(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::size_t> all;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    if (tracks_[j].writing) all.push_back(j);
  }
  for (const ActiveGoal& goal : goals_) all.insert(all.end(), goal.joints.begin(), goal.joints.end());
  endGoalsOn(all, false, Result::INVALID_GOAL, reason);
  hold(all, ros::Time::now().toSec());
}

void TrajectoryServer::onTick(const ros::TimerEvent&) {
  const double now = ros::Time::now().toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return;
  std::vector<JointSample> actual;
  bool velocity_known = false;
  const bool actual_fresh = actualState(&actual, now, &velocity_known);

  for (auto it = goals_.begin(); it != goals_.end();) {
    const bool over = superviseGoal(*it, now, actual, actual_fresh, velocity_known);
    it = over ? goals_.erase(it) : std::next(it);
  }

  // One frame for every joint a trajectory drives; a joint whose spline has ended is written
  // once more at its final position, then left to its servo.
  std::vector<std::string> names;
  std::vector<double> positions;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    Track& track = tracks_[j];
    if (!track.writing) continue;
    names.push_back(joints_.joints[j].name);
    positions.push_back(track.spline.sample(now).position);
    const bool owned = std::any_of(goals_.begin(), goals_.end(), [&](const ActiveGoal& goal) {
      return std::find(goal.joints.begin(), goal.joints.end(), j) != goal.joints.end();
    });
    if (!owned && now > track.spline.endTime()) track.writing = false;
    track.spline.prune(now);
  }
  if (names.empty()) return;
  const std::string error = joints_.write(names, positions);
  if (!error.empty()) ROS_WARN_THROTTLE(1.0, "trajectory: %s", error.c_str());
}

bool TrajectoryServer::superviseGoal(ActiveGoal& goal, double now,
                                     const std::vector<JointSample>& actual, bool actual_fresh,
                                     bool velocity_known) {
  if (!actual_fresh) {
    const std::string message =
        "telemetry lost: no state of the joints for more than 0.5 s, so nobody can tell whether "
        "they follow";
    static_assert(kTelemetryTimeout == 0.5, "the message says 0.5 s");
    ROS_WARN("follow_joint_trajectory: %s", message.c_str());
    hold(goal.joints, now);  // at the desired position: there is no measurement to stop at
    goal.handle.setAborted(result(Result::PATH_TOLERANCE_VIOLATED, message), message);
    return true;
  }
  std::vector<JointSample> desired, measured;
  serial_robot_driver::FollowJointTrajectoryFeedback feedback;
  feedback.header.stamp = ros::Time(now);
  feedback.joint_names = goal.names;
  const ros::Duration since_start(std::max(0.0, now - goal.start_time));
  feedback.desired.time_from_start = feedback.actual.time_from_start =
      feedback.error.time_from_start = since_start;
  for (std::size_t j : goal.joints) {
    const JointSample d = tracks_[j].spline.sample(now);
    JointSample a = actual[j];
    if (!velocity_known) a.velocity = d.velocity;  // unmeasured: never a violation
    desired.push_back(d);
    measured.push_back(a);
    feedback.desired.positions.push_back(d.position);
    feedback.desired.velocities.push_back(d.velocity);
    feedback.desired.accelerations.push_back(d.acceleration);
    feedback.actual.positions.push_back(a.position);
    if (velocity_known) feedback.actual.velocities.push_back(a.velocity);
    feedback.error.positions.push_back(d.position - a.position);
    if (velocity_known) feedback.error.velocities.push_back(d.velocity - a.velocity);
  }
  goal.handle.publishFeedback(feedback);

  if (now < goal.end_time) {
    const auto violation =
        trajectory::findViolation(goal.names, goal.path_tolerances, desired, measured, "path");
    if (!violation) return false;
    ROS_WARN("follow_joint_trajectory: aborted: %s", violation->message.c_str());
    hold(goal.joints, now);
    goal.handle.setAborted(result(Result::PATH_TOLERANCE_VIOLATED, violation->message),
                           violation->message);
    return true;
  }
  const auto violation =
      trajectory::findViolation(goal.names, goal.goal_tolerances, desired, measured, "goal");
  if (!violation) {
    goal.handle.setSucceeded(result(Result::SUCCESSFUL, ""), "reached");
    return true;
  }
  if (now <= goal.end_time + goal.goal_time_tolerance) return false;
  const std::string message = violation->message + " after the goal time tolerance";
  ROS_WARN("follow_joint_trajectory: aborted: %s", message.c_str());
  goal.handle.setAborted(result(Result::GOAL_TOLERANCE_VIOLATED, message), message);
  return true;
}

}  // namespace serial_robot_driver::ros_layer
