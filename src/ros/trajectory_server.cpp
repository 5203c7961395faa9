#include "serial_robot_driver/ros/trajectory_server.h"

#include "serial_robot_driver/ros/device_interface.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "serial_robot_driver/trajectory/bus_joint.h"

namespace serial_robot_driver::ros_layer {

namespace {

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

std::vector<TrajectoryJoints> DeviceInterface::trajectoryJoints() { return {}; }

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
                                   std::vector<TrajectoryJoints> groups)
    : defaults_(params.trajectory),
      groups_(std::move(groups)),
      loop_period_(1.0 / params.loop_rate),
      nh_(nh),
      action_server_(nh, "follow_joint_trajectory",
                     [this](GoalHandle handle) { onGoal(handle); },
                     [this](GoalHandle handle) { onCancel(handle); }, false) {
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    for (std::size_t local = 0; local < groups_[g].joints.size(); ++local) {
      index_[groups_[g].joints[local].name] = ranges_.size();
      ranges_.push_back(groups_[g].joints[local]);
      Track track;
      track.group = g;
      track.local = local;
      track.state_timeout = groups_[g].state_timeout;
      tracks_.push_back(track);
    }
  }
  actual_.resize(ranges_.size());
}

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
  const std::size_t count = std::min(state.name.size(), state.position.size());
  const bool velocity_known = state.velocity.size() >= count;
  const ros::Time stamp = state.header.stamp.isZero() ? ros::Time::now() : state.header.stamp;
  std::lock_guard<std::mutex> lock(actual_mutex_);
  for (std::size_t i = 0; i < count; ++i) {
    const auto joint = index_.find(state.name[i]);
    if (joint == index_.end()) continue;
    Measured& m = actual_[joint->second];
    m.sample.position = state.position[i];
    m.sample.velocity = velocity_known ? state.velocity[i] : 0.0;
    m.velocity_known = velocity_known;
    m.stamp = stamp;
  }
}

std::vector<TrajectoryServer::Measured> TrajectoryServer::measured() const {
  std::lock_guard<std::mutex> lock(actual_mutex_);
  return actual_;
}

long TrajectoryServer::staleJoint(const std::vector<Measured>& measured,
                                  const std::vector<std::size_t>& joints, double now) const {
  for (std::size_t j : joints) {
    if (measured[j].stamp.isZero() || now - measured[j].stamp.toSec() > tracks_[j].state_timeout) {
      return static_cast<long>(j);
    }
  }
  return -1;
}

void TrajectoryServer::retune(const TrajectoryParams& defaults) {
  std::lock_guard<std::mutex> lock(mutex_);
  defaults_ = defaults;
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
      trajectory::validate(command, ranges_, defaults_.max_velocity, start - now);
  if (!result.ok()) return result;
  const std::vector<Measured> actual = measured();
  const long stale = staleJoint(actual, result.joint_indices, now);
  if (stale >= 0 && !command.points.empty()) {
    result.error = CommandError::kInvalidGoal;
    result.message = "joint '" + ranges_[stale].name +
                     "': no recent measurement (is its telemetry or poll arriving?), so the "
                     "trajectory cannot start from where it is";
    return result;
  }
  if (defaults_.max_velocity > 0.0) {
    // The bridge starts from the desired state where a trajectory runs, else from the measurement.
    std::vector<double> current;
    for (std::size_t j : result.joint_indices) {
      current.push_back(tracks_[j].writing ? tracks_[j].spline.sample(now).position
                                           : actual[j].sample.position);
    }
    result = trajectory::validate(command, ranges_, defaults_.max_velocity, start - now, current);
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
  const std::vector<Measured> actual = measured();
  for (std::size_t column = 0; column < joints.size(); ++column) {
    Track& track = tracks_[joints[column]];
    // A joint nobody drives starts from where it is; a driven one from where it is meant to be.
    if (!track.writing) {
      track.spline = trajectory::JointSpline(actual[joints[column]].sample.position);
    }
    track.spline.splice(std::max(start, now), trajectory::waypointsFor(command, column, start, now));
    track.writing = true;
    track.hold_pending = false;
    track.sent_segment = -1.0;  // no segment starts before the epoch
  }
}

void TrajectoryServer::hold(const std::vector<std::size_t>& joints, double now) {
  const std::vector<Measured> actual = measured();
  for (std::size_t j : joints) {
    const std::vector<std::size_t> one{j};
    const double position = staleJoint(actual, one, now) < 0 ? actual[j].sample.position
                                                              : tracks_[j].spline.sample(now).position;
    tracks_[j].spline = trajectory::JointSpline(position);
    tracks_[j].writing = true;  // written once, then the servo keeps it
    tracks_[j].hold_pending = true;
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
  if (e_stop_ && e_stop_->refuse("follow_joint_trajectory")) {
    ROS_WARN("follow_joint_trajectory: goal rejected: e_stop is engaged");
    handle.setRejected(result(Result::INVALID_GOAL, "e_stop is engaged"), "e_stop is engaged");
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
  if (e_stop_ && e_stop_->refuse("joint_trajectory")) {
    ROS_WARN_THROTTLE(1.0, "joint_trajectory: message ignored, nothing moves: e_stop is engaged");
    return;
  }
  const trajectory::CommandCheck checked = check(command, start, now);
  if (!checked.ok()) {
    ROS_WARN_THROTTLE(1.0, "joint_trajectory: message ignored, nothing moves: %s",
                      checked.message.c_str());
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
    const auto joint = index_.find(name);
    if (joint == index_.end() || !tracks_[joint->second].writing) continue;
    tracks_[joint->second].writing = false;
    taken.push_back(joint->second);
  }
  if (taken.empty()) return;
  const std::string message = "joint '" + ranges_[taken.front()].name + "' taken over by " +
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

void TrajectoryServer::attachEStop(device::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) {
    if (engaged) stopAll("e_stop engaged");
  });
}

void TrajectoryServer::onTick(const ros::TimerEvent&) {
  const double now = ros::Time::now().toSec();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return;
  // Idle (the usual case) costs one scan of the tracks.
  const bool busy = !goals_.empty() || std::any_of(tracks_.begin(), tracks_.end(),
                                                   [](const Track& t) { return t.writing; });
  if (!busy) return;
  const std::vector<Measured> actual = measured();
  for (auto it = goals_.begin(); it != goals_.end();) {
    it = superviseGoal(*it, now, actual) ? goals_.erase(it) : std::next(it);
  }
  writeTracks(now);
}

void TrajectoryServer::writeTracks(double now) {
  // Streamed groups: one frame for every joint a trajectory drives. Per-segment groups: a move at
  // each segment's start. A joint whose spline has ended is written once more at its final
  // position (streamed), then left to its servo.
  std::vector<std::vector<std::string>> names(groups_.size());
  std::vector<std::vector<double>> positions(groups_.size());
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    Track& track = tracks_[j];
    if (!track.writing) continue;
    const TrajectoryJoints& group = groups_[track.group];
    if (group.move) {
      std::string error;
      if (track.hold_pending) {
        error = group.move(track.local, track.spline.sample(now).position, 0.0);
      } else if (const auto move = trajectory::segmentMoveAt(track.spline, now, track.sent_segment)) {
        error = group.move(track.local, move->position, move->duration);
        track.sent_segment = move->segment_start;
      }
      if (!error.empty()) ROS_WARN_THROTTLE(1.0, "trajectory: %s", error.c_str());
    } else {
      names[track.group].push_back(ranges_[j].name);
      positions[track.group].push_back(track.spline.sample(now).position);
    }
    track.hold_pending = false;
    const bool owned = std::any_of(goals_.begin(), goals_.end(), [&](const ActiveGoal& goal) {
      return std::find(goal.joints.begin(), goal.joints.end(), j) != goal.joints.end();
    });
    if (!owned && now > track.spline.endTime()) track.writing = false;
    track.spline.prune(now);
  }
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (names[g].empty() || !groups_[g].write) continue;
    const std::string error = groups_[g].write(names[g], positions[g]);
    if (!error.empty()) ROS_WARN_THROTTLE(1.0, "trajectory: %s", error.c_str());
  }
}

bool TrajectoryServer::superviseGoal(ActiveGoal& goal, double now,
                                     const std::vector<Measured>& actual) {
  const long stale = staleJoint(actual, goal.joints, now);
  if (stale >= 0) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "telemetry lost: no state of joint '%s' for more than %.1f s, so nobody can tell "
                  "whether it follows",
                  ranges_[stale].name.c_str(), tracks_[stale].state_timeout);
    const std::string message = text;
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
  const bool velocity_known = std::all_of(goal.joints.begin(), goal.joints.end(),
                                          [&](std::size_t j) { return actual[j].velocity_known; });
  for (std::size_t j : goal.joints) {
    const JointSample d = tracks_[j].spline.sample(now);
    JointSample a = actual[j].sample;
    if (!actual[j].velocity_known) a.velocity = d.velocity;  // unmeasured: never a violation
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
