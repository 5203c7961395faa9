#include "serial_robot_driver/ros/trajectory_server.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "serial_robot_driver/ros/device_interface.h"
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

/// "; joint 'a', 'b' left alone: ..." for the joints a stop could not hold, "" when none.
std::string leftAloneText(const std::vector<std::string>& names) {
  if (names.empty()) return "";
  std::string text = names.size() == 1 ? "joint " : "joints ";
  for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", '" : "'") + names[i] + "'";
  return text +
         " left alone: never commanded by the driver nor recently measured, so there is no "
         "position to hold";
}

/// `base`, then `; left_alone` when there is one.
std::string withLeftAlone(const std::string& base, const std::string& left_alone) {
  if (left_alone.empty()) return base;
  return base.empty() ? left_alone : base + "; " + left_alone;
}

}  // namespace

double steadyNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double steadyStart(const ros::Time& stamp, double steady_now, const ros::Time& ros_now) {
  if (stamp.isZero()) return steady_now;
  return steady_now + (stamp - ros_now).toSec();
}

std::optional<double> streamedHoldPosition(std::optional<double> last_written,
                                           std::optional<double> last_commanded,
                                           std::optional<double> fresh_measurement) {
  if (last_written) return last_written;
  if (last_commanded) return last_commanded;
  return fresh_measurement;
}

std::vector<TrajectoryJoints> DeviceInterface::trajectoryJoints() { return {}; }

trajectory::TrajectoryCommand toTrajectoryCommand(const trajectory_msgs::JointTrajectory& msg) {
  trajectory::TrajectoryCommand command;
  command.joint_names = msg.joint_names;
  for (const auto& point : msg.points) {
    command.points.push_back(
        {point.time_from_start.toSec(), point.positions, point.velocities, point.accelerations});
  }
  return command;
}

TrajectoryServer::TrajectoryServer(ros::NodeHandle& nh, const DriverParams& params,
                                   std::vector<TrajectoryJoints> groups)
    : defaults_(params.trajectory),
      groups_(std::move(groups)),
      loop_period_(1.0 / params.loop_rate),
      nh_(nh),
      action_server_(
          nh, "follow_joint_trajectory", [this](GoalHandle handle) { onGoal(handle); },
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
  // Steady: a step of the ROS or wall clock must not skip or replay a trajectory.
  timer_ = nh_.createSteadyTimer(ros::WallDuration(loop_period_), &TrajectoryServer::onTick, this);
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
  // Freshness is the steady time of receipt: the header's stamp is on a clock that may step.
  const double received = steadyNow();
  std::lock_guard<std::mutex> lock(actual_mutex_);
  for (std::size_t i = 0; i < count; ++i) {
    const auto joint = index_.find(state.name[i]);
    if (joint == index_.end()) continue;
    Measured& m = actual_[joint->second];
    m.sample.position = state.position[i];
    m.sample.velocity = velocity_known ? state.velocity[i] : 0.0;
    m.velocity_known = velocity_known;
    m.received = received;
  }
}

std::vector<TrajectoryServer::Measured> TrajectoryServer::measured() const {
  std::lock_guard<std::mutex> lock(actual_mutex_);
  return actual_;
}

long TrajectoryServer::staleJoint(const std::vector<Measured>& measured,
                                  const std::vector<std::size_t>& joints, double now) const {
  for (std::size_t j : joints) {
    if (!measured[j].received || now - *measured[j].received > tracks_[j].state_timeout) {
      return static_cast<long>(j);
    }
  }
  return -1;
}

void TrajectoryServer::retune(const TrajectoryParams& defaults) {
  std::lock_guard<std::mutex> lock(mutex_);
  defaults_ = defaults;
}

void TrajectoryServer::setStateTimeout(const std::vector<std::string>& names, double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const std::string& name : names) {
    const auto joint = index_.find(name);
    if (joint != index_.end()) tracks_[joint->second].state_timeout = seconds;
  }
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
    track.spline.splice(std::max(start, now),
                        trajectory::waypointsFor(command, column, start, now));
    track.writing = true;
    track.sent_segment = -std::numeric_limits<double>::infinity();  // no move went out yet
  }
}

std::string TrajectoryServer::hold(const std::vector<std::size_t>& joints, double now) {
  const std::vector<Measured> actual = measured();
  std::vector<std::string> left_alone;
  for (std::size_t j : joints) {
    Track& track = tracks_[j];
    const TrajectoryJoints& group = groups_[track.group];
    if (group.move) {
      // Per-segment: a stop where the servo is, never a move to an angle that may be stale. The
      // desired state is the spline now (feedback, and where a later goal bridges from).
      if (!track.writing && !track.moved) {
        left_alone.push_back(ranges_[j].name);
        continue;
      }
      track.spline = trajectory::JointSpline(track.spline.sample(now).position);
      track.writing = true;  // until the next tick: it has nothing more to send
      const std::string error = group.stop ? group.stop(track.local) : std::string();
      if (!error.empty()) ROS_WARN_THROTTLE(1.0, "trajectory: %s", error.c_str());
      continue;
    }
    // Streamed: where it was last commanded, by this server, else by anyone; never commanded, where
    // it is measured if that is fresh; else nothing is written for it.
    const std::optional<double> position = streamedHoldPosition(
        track.last_written, group.last_commanded ? group.last_commanded(track.local) : std::nullopt,
        staleJoint(actual, {j}, now) < 0 ? std::optional<double>(actual[j].sample.position)
                                         : std::nullopt);
    if (!position) {
      track.writing = false;
      left_alone.push_back(ranges_[j].name);
      continue;
    }
    track.spline = trajectory::JointSpline(*position);
    track.writing = true;  // written once, then the servo keeps it
  }
  return leftAloneText(left_alone);
}

void TrajectoryServer::onGoal(GoalHandle handle) {
  const auto goal = handle.getGoal();
  const trajectory::TrajectoryCommand command = toTrajectoryCommand(goal->trajectory);
  const double now = steadyNow();
  const double start = steadyStart(goal->trajectory.header.stamp, now, ros::Time::now());
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
    const std::string left_alone = hold(checked.joint_indices, now);
    if (!left_alone.empty()) ROS_WARN("follow_joint_trajectory: stop: %s", left_alone.c_str());
    handle.setSucceeded(result(Result::SUCCESSFUL, left_alone),
                        withLeftAlone("stopped where they were last commanded", left_alone));
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
  const std::string message = withLeftAlone("cancelled: holding where they were last commanded",
                                            hold(it->joints, steadyNow()));
  it->handle.setCanceled(result(Result::SUCCESSFUL, message), message);
  goals_.erase(it);
}

void TrajectoryServer::onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
  const trajectory::TrajectoryCommand command = toTrajectoryCommand(*msg);
  const double now = steadyNow();
  const double start = steadyStart(msg->header.stamp, now, ros::Time::now());
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
    const std::string left_alone = hold(checked.joint_indices, now);
    if (!left_alone.empty()) ROS_WARN("joint_trajectory: stop: %s", left_alone.c_str());
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
    if (joint == index_.end()) continue;
    // What this server wrote is no longer the joint's last command.
    tracks_[joint->second].last_written.reset();
    if (!tracks_[joint->second].writing) continue;
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
  for (const ActiveGoal& goal : goals_)
    all.insert(all.end(), goal.joints.begin(), goal.joints.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  const std::string left_alone = hold(all, steadyNow());
  endGoalsOn(all, false, Result::INVALID_GOAL, withLeftAlone(reason, left_alone));
}

void TrajectoryServer::attachEStop(device::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) {
    if (engaged) stopAll("e_stop engaged");
  });
}

void TrajectoryServer::onTick(const ros::SteadyTimerEvent&) {
  const double now = steadyNow();
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
      if (const auto move = trajectory::segmentMoveAt(track.spline, now, track.sent_segment)) {
        const std::string error = group.move(track.local, move->position, move->duration);
        track.sent_segment = move->segment_start;
        if (error.empty()) track.moved = true;
        if (!error.empty()) ROS_WARN_THROTTLE(1.0, "trajectory: %s", error.c_str());
      }
    } else {
      names[track.group].push_back(ranges_[j].name);
      positions[track.group].push_back(track.spline.sample(now).position);
    }
    const bool owned = std::any_of(goals_.begin(), goals_.end(), [&](const ActiveGoal& goal) {
      return std::find(goal.joints.begin(), goal.joints.end(), j) != goal.joints.end();
    });
    if (!owned && now > track.spline.endTime()) track.writing = false;
    track.spline.prune(now);
  }
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (names[g].empty() || !groups_[g].write) continue;
    const std::string error = groups_[g].write(names[g], positions[g]);
    if (!error.empty()) {
      ROS_WARN_THROTTLE(1.0, "trajectory: %s", error.c_str());
      continue;
    }
    for (std::size_t k = 0; k < names[g].size(); ++k) {
      tracks_[index_.at(names[g][k])].last_written = positions[g][k];
    }
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
    // Held where last commanded: there is no measurement to stop at.
    const std::string message = withLeftAlone(text, hold(goal.joints, now));
    ROS_WARN("follow_joint_trajectory: %s", message.c_str());
    goal.handle.setAborted(result(Result::PATH_TOLERANCE_VIOLATED, message), message);
    return true;
  }
  std::vector<JointSample> desired, measured;
  serial_robot_driver::FollowJointTrajectoryFeedback feedback;
  feedback.header.stamp = ros::Time::now();  // ROS time, as every stamp; `now` is steady
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
    const std::string message = withLeftAlone(violation->message, hold(goal.joints, now));
    ROS_WARN("follow_joint_trajectory: aborted: %s", message.c_str());
    goal.handle.setAborted(result(Result::PATH_TOLERANCE_VIOLATED, message), message);
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
