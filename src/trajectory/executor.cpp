#include "serial_robot_driver/trajectory/executor.h"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "serial_robot_driver/trajectory/command_start.h"

namespace serial_robot_driver::trajectory {

TrajectoryExecutor::TrajectoryExecutor(std::vector<TrajectoryJoints> groups,
                                       const GoalDefaults& defaults, Clock clock, Warn warn)
    : groups_(std::move(groups)),
      clock_(std::move(clock)),
      warn_(std::move(warn)),
      defaults_(defaults) {
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
  writing_.assign(tracks_.size(), false);
  actual_.resize(ranges_.size());
}

void TrajectoryExecutor::warn(const std::string& text) const {
  if (warn_) warn_(text);
}

void TrajectoryExecutor::warnThrottled(ThrottledWarning kind, const std::string& text, double now) {
  std::optional<double>& last = last_warned_[kind];
  if (last && now - *last < 1.0) return;
  last = now;
  warn(text);
}

bool TrajectoryExecutor::start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_) return false;
  running_ = true;
  if (busyLocked()) setTickingLocked(true);
  return true;
}

void TrajectoryExecutor::setTicker(std::function<void(bool on)> ticker) {
  std::lock_guard<std::mutex> lock(mutex_);
  ticker_ = std::move(ticker);
  ticking_ = false;
  if (busyLocked()) setTickingLocked(true);
}

void TrajectoryExecutor::shutdown() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return;
  running_ = false;
  for (const ActiveGoal& goal : goals_) {
    finish(goal.callbacks,
           outcome(GoalStatus::kAborted, result_code::kInvalidGoal, "the driver is shutting down"));
  }
  goals_.clear();
}

void TrajectoryExecutor::updateActual(const std::vector<std::string>& names,
                                      const std::vector<double>& positions,
                                      const std::vector<double>& velocities) {
  updateActual(tracksOf(names), positions, velocities);
}

std::vector<std::size_t> TrajectoryExecutor::tracksOf(const std::vector<std::string>& names) const {
  std::vector<std::size_t> tracks;
  tracks.reserve(names.size());
  for (const std::string& name : names) {
    const auto joint = index_.find(name);
    tracks.push_back(joint == index_.end() ? kNoTrack : joint->second);
  }
  return tracks;
}

void TrajectoryExecutor::updateActual(const std::vector<std::size_t>& tracks,
                                      const std::vector<double>& positions,
                                      const std::vector<double>& velocities) {
  const std::size_t count = std::min(tracks.size(), positions.size());
  const bool velocity_known = velocities.size() >= count;
  // Freshness is the time of receipt: a message's stamp is on a clock that may step.
  const double received = now();
  std::lock_guard<std::mutex> lock(actual_mutex_);
  for (std::size_t i = 0; i < count; ++i) {
    if (tracks[i] >= actual_.size()) continue;  // kNoTrack
    Measured& m = actual_[tracks[i]];
    m.sample.position = positions[i];
    m.sample.velocity = velocity_known ? velocities[i] : 0.0;
    m.velocity_known = velocity_known;
    m.received = received;
  }
}

std::vector<TrajectoryExecutor::Measured> TrajectoryExecutor::measured() const {
  std::lock_guard<std::mutex> lock(actual_mutex_);
  return actual_;
}

long TrajectoryExecutor::staleJoint(const std::vector<Measured>& measured,
                                    const std::vector<std::size_t>& joints, double now) const {
  for (std::size_t j : joints) {
    if (!measured[j].received || now - *measured[j].received > tracks_[j].state_timeout) {
      return static_cast<long>(j);
    }
  }
  return -1;
}

void TrajectoryExecutor::retune(const GoalDefaults& defaults) {
  std::lock_guard<std::mutex> lock(mutex_);
  defaults_ = defaults;
}

void TrajectoryExecutor::setStateTimeout(const std::vector<std::string>& names, double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const std::string& name : names) {
    const auto joint = index_.find(name);
    if (joint != index_.end()) tracks_[joint->second].state_timeout = seconds;
  }
}

CommandCheck TrajectoryExecutor::check(const TrajectoryCommand& command, double start, double now) {
  CommandCheck result = validate(command, ranges_, defaults_.max_velocity, start - now);
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
      current.push_back(writing_[j] ? tracks_[j].spline.sample(now).position
                                    : actual[j].sample.position);
    }
    result = validate(command, ranges_, defaults_.max_velocity, start - now, current);
  }
  return result;
}

TrajectoryExecutor::Generations TrajectoryExecutor::generations() const {
  Generations now;
  for (const TrajectoryJoints& group : groups_) {
    now.push_back(group.generation ? std::optional<uint64_t>(group.generation()) : std::nullopt);
  }
  return now;
}

bool TrajectoryExecutor::voided(std::size_t j) const {
  const Track& track = tracks_[j];
  const TrajectoryJoints& group = groups_[track.group];
  return group.generation && track.accepted && *track.accepted != group.generation();
}

void TrajectoryExecutor::dropVoided(const std::vector<std::size_t>& joints, double now) {
  if (joints.empty()) return;
  for (std::size_t j : joints) writing_[j] = false;
  const std::string message = "trajectory of joint '" + ranges_[joints.front()].name +
                              "' dropped: e-stop engaged after this command was accepted";
  warnThrottled(kTrajectoryError, message, now);
  endGoalsOn(goals_, joints, GoalStatus::kAborted, result_code::kInvalidGoal, message);
}

void TrajectoryExecutor::apply(const TrajectoryCommand& command,
                               const std::vector<std::size_t>& joints, double start, double now,
                               const Generations& accepted) {
  const std::vector<Measured> actual = measured();
  for (std::size_t column = 0; column < joints.size(); ++column) {
    const std::size_t j = joints[column];
    Track& track = tracks_[j];
    track.accepted = accepted[track.group];
    // A joint nobody drives starts from where it is; a driven one from where it is meant to be.
    if (!writing_[j]) track.spline = JointSpline(actual[j].sample.position);
    track.spline.splice(std::max(start, now), waypointsFor(command, column, start, now));
    writing_[j] = true;
    track.sent_segment = -std::numeric_limits<double>::infinity();  // no move went out yet
  }
  setTickingLocked(true);
}

std::string TrajectoryExecutor::hold(const std::vector<std::size_t>& joints, double now) {
  const std::vector<Measured> actual = measured();
  // A hold is accepted now: the e-stop's own (stopAll) is voided by that e-stop, so it is never
  // written once it is released.
  const Generations accepted = generations();
  std::vector<std::string> left_alone;
  for (std::size_t j : joints) {
    Track& track = tracks_[j];
    const TrajectoryJoints& group = groups_[track.group];
    track.accepted = accepted[track.group];
    if (group.move) {
      // Per-segment: a stop where the servo is, never a move to an angle that may be stale. The
      // desired state is the spline now (feedback, and where a later goal bridges from).
      if (!writing_[j] && !track.moved) {
        left_alone.push_back(ranges_[j].name);
        continue;
      }
      track.spline = JointSpline(track.spline.sample(now).position);
      writing_[j] = true;  // until the next tick: it has nothing more to send
      const std::string error = group.stop ? group.stop(track.local) : std::string();
      if (!error.empty()) warnThrottled(kTrajectoryError, "trajectory: " + error, now);
      continue;
    }
    // Streamed: where it was last commanded, by this executor, else by anyone; never commanded,
    // where it is measured if that is fresh; else nothing is written for it.
    const std::optional<double> position = streamedHoldPosition(
        track.last_written, group.last_commanded ? group.last_commanded(track.local) : std::nullopt,
        staleJoint(actual, {j}, now) < 0 ? std::optional<double>(actual[j].sample.position)
                                         : std::nullopt);
    if (!position) {
      writing_[j] = false;
      left_alone.push_back(ranges_[j].name);
      continue;
    }
    track.spline = JointSpline(*position);
    writing_[j] = true;  // written once, then the servo keeps it
  }
  if (busyLocked()) setTickingLocked(true);
  return leftAloneText(left_alone);
}

TrajectoryExecutor::Submission TrajectoryExecutor::submitGoal(const Goal& goal,
                                                              GoalCallbacks callbacks) {
  const TrajectoryCommand& command = goal.command;
  // Accepted now: noted before the e-stop check, so an e-stop from here on voids it.
  const Generations accepted = generations();
  const double now = this->now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) {
    finish(callbacks,
           outcome(GoalStatus::kRejected, result_code::kInvalidGoal, "the driver is not running"));
    return Submission::kNotRunning;
  }
  if (e_stop_ && e_stop_->refuse("follow_joint_trajectory")) {
    warn("follow_joint_trajectory: goal rejected: e_stop is engaged");
    finish(callbacks,
           outcome(GoalStatus::kRejected, result_code::kInvalidGoal, "e_stop is engaged"));
    return Submission::kEStopped;
  }
  CommandCheck checked;
  const std::optional<double> started =
      startOf(command, goal.start_time, now, defaults_.max_start_delay, &checked);
  if (started) checked = check(command, *started, now);
  if (!checked.ok()) {
    warn("follow_joint_trajectory: goal rejected: " + checked.message);
    finish(callbacks, outcome(GoalStatus::kRejected, resultCode(checked.error), checked.message));
    return Submission::kInvalid;
  }
  const double start = *started;
  if (callbacks.accepted) callbacks.accepted();
  endGoalsOn(goals_, checked.joint_indices, GoalStatus::kCanceled, result_code::kSuccessful,
             "preempted by a new goal");
  if (command.points.empty()) {
    // joint_trajectory_controller's "stop": hold where they are, and that is done at once.
    const std::string left_alone = hold(checked.joint_indices, now);
    if (!left_alone.empty()) warn("follow_joint_trajectory: stop: " + left_alone);
    finish(callbacks, outcome(GoalStatus::kSucceeded, result_code::kSuccessful, left_alone,
                              withLeftAlone("stopped where they were last commanded", left_alone)));
    return Submission::kAccepted;
  }
  apply(command, checked.joint_indices, start, now, accepted);

  goals_.push_back(admitGoal(goal, std::move(callbacks), checked.joint_indices, start, defaults_));
  return Submission::kAccepted;
}

void TrajectoryExecutor::cancelGoal(const std::string& id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = std::find_if(goals_.begin(), goals_.end(),
                         [&](const ActiveGoal& goal) { return goal.id == id; });
  if (it == goals_.end()) return;  // already over
  const std::string message =
      withLeftAlone("cancelled: holding where they were last commanded", hold(it->joints, now()));
  finish(it->callbacks, outcome(GoalStatus::kCanceled, result_code::kSuccessful, message));
  goals_.erase(it);
}

TrajectoryExecutor::Submission TrajectoryExecutor::submitTrajectory(
    const TrajectoryCommand& command, std::optional<double> start_time) {
  const Generations accepted = generations();  // before the e-stop check, as submitGoal()
  const double now = this->now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return Submission::kNotRunning;
  if (e_stop_ && e_stop_->refuse("joint_trajectory")) {
    warnThrottled(kMessageRefused,
                  "joint_trajectory: message ignored, nothing moves: e_stop is engaged", now);
    return Submission::kEStopped;
  }
  CommandCheck checked;
  const std::optional<double> start =
      startOf(command, start_time, now, defaults_.max_start_delay, &checked);
  if (start) checked = check(command, *start, now);
  if (!checked.ok()) {
    warnThrottled(kMessageInvalid,
                  "joint_trajectory: message ignored, nothing moves: " + checked.message, now);
    return Submission::kInvalid;
  }
  endGoalsOn(goals_, checked.joint_indices, GoalStatus::kCanceled, result_code::kSuccessful,
             "preempted by a joint_trajectory message");
  if (command.points.empty()) {
    const std::string left_alone = hold(checked.joint_indices, now);
    if (!left_alone.empty()) warn("joint_trajectory: stop: " + left_alone);
  } else {
    apply(command, checked.joint_indices, *start, now, accepted);
  }
  return Submission::kAccepted;
}

void TrajectoryExecutor::takeOver(const std::vector<std::string>& names, const std::string& source,
                                  const std::function<bool()>& write) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!write()) return;
  std::vector<std::size_t> taken;
  for (const std::string& name : names) {
    const auto joint = index_.find(name);
    if (joint == index_.end()) continue;
    // What this executor wrote is no longer the joint's last command.
    tracks_[joint->second].last_written.reset();
    if (!writing_[joint->second]) continue;
    writing_[joint->second] = false;
    taken.push_back(joint->second);
  }
  if (taken.empty()) return;
  const std::string message = "joint '" + ranges_[taken.front()].name + "' taken over by " +
                              source + ": trajectory stopped";
  warn(message);
  endGoalsOn(goals_, taken, GoalStatus::kAborted, result_code::kInvalidGoal, message);
}

void TrajectoryExecutor::stopAll(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::size_t> all;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    if (writing_[j]) all.push_back(j);
  }
  for (const ActiveGoal& goal : goals_)
    all.insert(all.end(), goal.joints.begin(), goal.joints.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  const std::string left_alone = hold(all, now());
  endGoalsOn(goals_, all, GoalStatus::kAborted, result_code::kInvalidGoal,
             withLeftAlone(reason, left_alone));
}

void TrajectoryExecutor::attachEStop(core::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) {
    if (engaged) stopAll("e_stop engaged");
  });
}

void TrajectoryExecutor::tick() {
  const double now = this->now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return;
  // Idle costs one scan of the tracks (and with a ticker, no tick until there is work again).
  if (busyLocked()) {
    const std::vector<Measured> actual = measured();
    for (auto it = goals_.begin(); it != goals_.end();) {
      it = superviseGoal(*it, now, actual) ? goals_.erase(it) : std::next(it);
    }
    writeTracks(now);
  }
  if (!busyLocked()) setTickingLocked(false);
}

bool TrajectoryExecutor::busyLocked() const {
  return !goals_.empty() ||
         std::any_of(writing_.begin(), writing_.end(), [](uint8_t writing) { return writing; });
}

void TrajectoryExecutor::setTickingLocked(bool on) {
  if (!ticker_ || !running_ || on == ticking_) return;
  ticking_ = on;
  ticker_(on);
}

void TrajectoryExecutor::writeTracks(double now) {
  // Streamed groups: one frame for every joint a trajectory drives. Per-segment groups: a move at
  // each segment's start. A joint whose spline has ended is written once more at its final
  // position (streamed), then left to its servo.
  std::vector<std::vector<std::string>> names(groups_.size());
  std::vector<std::vector<double>> positions(groups_.size());
  std::vector<std::optional<uint64_t>> frame_accepted(groups_.size());  // the oldest in the frame
  std::vector<std::size_t> voided_joints;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    Track& track = tracks_[j];
    if (!writing_[j]) continue;
    const TrajectoryJoints& group = groups_[track.group];
    if (voided(j)) {
      voided_joints.push_back(j);
      continue;
    }
    if (track.accepted) {
      std::optional<uint64_t>& oldest = frame_accepted[track.group];
      oldest = oldest ? std::min(*oldest, *track.accepted) : *track.accepted;
    }
    if (group.move) {
      if (const auto move = segmentMoveAt(track.spline, now, track.sent_segment)) {
        const std::string error = group.move(track.local, move->position, move->duration);
        track.sent_segment = move->segment_start;
        if (error.empty()) track.moved = true;
        if (!error.empty()) warnThrottled(kTrajectoryError, "trajectory: " + error, now);
      }
    } else {
      names[track.group].push_back(ranges_[j].name);
      positions[track.group].push_back(track.spline.sample(now).position);
    }
    const bool owned = std::any_of(goals_.begin(), goals_.end(), [&](const ActiveGoal& goal) {
      return std::find(goal.joints.begin(), goal.joints.end(), j) != goal.joints.end();
    });
    if (!owned && now > track.spline.endTime()) writing_[j] = false;
    track.spline.prune(now);
  }
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (names[g].empty() || !groups_[g].write) continue;
    // Through the device's gate with the generation it was accepted under: an e-stop engaged
    // since this check (after the tracks were read) still voids the frame.
    const std::string error = groups_[g].write(names[g], positions[g], frame_accepted[g]);
    if (!error.empty()) {
      warnThrottled(kTrajectoryError, "trajectory: " + error, now);
      for (const std::string& name : names[g]) {
        if (voided(index_.at(name))) voided_joints.push_back(index_.at(name));
      }
      continue;
    }
    for (std::size_t k = 0; k < names[g].size(); ++k) {
      tracks_[index_.at(names[g][k])].last_written = positions[g][k];
    }
  }
  dropVoided(voided_joints, now);
}

bool TrajectoryExecutor::jointInMotionLocked(std::size_t j) const {
  return writing_[j] || std::any_of(goals_.begin(), goals_.end(), [j](const ActiveGoal& goal) {
           return std::find(goal.joints.begin(), goal.joints.end(), j) != goal.joints.end();
         });
}

bool TrajectoryExecutor::inMotion() {
  std::lock_guard<std::mutex> lock(mutex_);
  // A goal always holds a joint (one without points is done at once), so "busy" is "a joint in
  // motion"; asked once per telemetry frame, it reads one byte per track.
  return busyLocked();
}

std::string TrajectoryExecutor::motionInForce() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> moving;
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    if (jointInMotionLocked(j)) moving.push_back(ranges_[j].name);
  }
  if (moving.empty()) return {};
  std::string text = "trajectory in progress (";
  for (std::size_t i = 0; i < moving.size(); ++i) text += (i ? ", '" : "'") + moving[i] + "'";
  return text + ")";
}

bool TrajectoryExecutor::superviseGoal(ActiveGoal& goal, double now,
                                       const std::vector<Measured>& actual) {
  if (abortIfTelemetryLost(goal, now, actual)) return true;
  std::vector<JointSample> desired, measured;
  sampleAndReport(goal, now, actual, &desired, &measured);
  return judgeTolerances(goal, now, desired, measured);
}

bool TrajectoryExecutor::abortIfTelemetryLost(ActiveGoal& goal, double now,
                                              const std::vector<Measured>& actual) {
  const long stale = staleJoint(actual, goal.joints, now);
  if (stale < 0) return false;
  char text[200];
  std::snprintf(text, sizeof(text),
                "telemetry lost: no state of joint '%s' for more than %.1f s, so nobody can tell "
                "whether it follows",
                ranges_[stale].name.c_str(), tracks_[stale].state_timeout);
  // Held where last commanded: there is no measurement to stop at.
  const std::string message = withLeftAlone(text, hold(goal.joints, now));
  warn("follow_joint_trajectory: " + message);
  finish(goal.callbacks,
         outcome(GoalStatus::kAborted, result_code::kPathToleranceViolated, message));
  return true;
}

void TrajectoryExecutor::sampleAndReport(const ActiveGoal& goal, double now,
                                         const std::vector<Measured>& actual,
                                         std::vector<JointSample>* desired,
                                         std::vector<JointSample>* measured) {
  GoalFeedback feedback;
  feedback.joint_names = goal.names;
  feedback.time_from_start = std::max(0.0, now - goal.start_time);
  const bool velocity_known = std::all_of(goal.joints.begin(), goal.joints.end(),
                                          [&](std::size_t j) { return actual[j].velocity_known; });
  for (std::size_t j : goal.joints) {
    const JointSample d = tracks_[j].spline.sample(now);
    JointSample a = actual[j].sample;
    if (!actual[j].velocity_known) a.velocity = d.velocity;  // unmeasured: never a violation
    desired->push_back(d);
    measured->push_back(a);
    feedback.actual_positions.push_back(a.position);
    feedback.error_positions.push_back(d.position - a.position);
    if (velocity_known) {
      feedback.actual_velocities.push_back(a.velocity);
      feedback.error_velocities.push_back(d.velocity - a.velocity);
    }
  }
  feedback.desired = *desired;
  if (goal.callbacks.feedback) goal.callbacks.feedback(feedback);
}

bool TrajectoryExecutor::judgeTolerances(ActiveGoal& goal, double now,
                                         const std::vector<JointSample>& desired,
                                         const std::vector<JointSample>& measured) {
  if (now < goal.end_time) {
    const auto violation =
        findViolation(goal.names, goal.path_tolerances, desired, measured, "path");
    if (!violation) return false;
    const std::string message = withLeftAlone(violation->message, hold(goal.joints, now));
    warn("follow_joint_trajectory: aborted: " + message);
    finish(goal.callbacks,
           outcome(GoalStatus::kAborted, result_code::kPathToleranceViolated, message));
    return true;
  }
  const auto violation = findViolation(goal.names, goal.goal_tolerances, desired, measured, "goal");
  if (!violation) {
    finish(goal.callbacks,
           outcome(GoalStatus::kSucceeded, result_code::kSuccessful, "", "reached"));
    return true;
  }
  if (now <= goal.end_time + goal.goal_time_tolerance) return false;
  const std::string message = violation->message + " after the goal time tolerance";
  warn("follow_joint_trajectory: aborted: " + message);
  finish(goal.callbacks,
         outcome(GoalStatus::kAborted, result_code::kGoalToleranceViolated, message));
  return true;
}

}  // namespace serial_robot_driver::trajectory
