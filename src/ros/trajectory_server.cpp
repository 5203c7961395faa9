#include "serial_robot_driver/ros/trajectory_server.h"

#include <cstdint>
#include <string>

#include "serial_robot_driver/ros/guarded_callbacks.h"

namespace serial_robot_driver::ros_layer {

namespace {

using Result = serial_robot_driver::FollowJointTrajectoryResult;
using Submission = trajectory::TrajectoryExecutor::Submission;
namespace code = trajectory::result_code;
static_assert(code::kSuccessful == Result::SUCCESSFUL &&
              code::kInvalidGoal == Result::INVALID_GOAL &&
              code::kInvalidJoints == Result::INVALID_JOINTS &&
              code::kOldHeaderTimestamp == Result::OLD_HEADER_TIMESTAMP &&
              code::kPathToleranceViolated == Result::PATH_TOLERANCE_VIOLATED &&
              code::kGoalToleranceViolated == Result::GOAL_TOLERANCE_VIOLATED);

std::vector<trajectory::NamedTolerance> fromMsg(
    const std::vector<serial_robot_driver::JointTolerance>& list) {
  std::vector<trajectory::NamedTolerance> result;
  for (const auto& entry : list) result.push_back({entry.name, entry.position, entry.velocity});
  return result;
}

serial_robot_driver::FollowJointTrajectoryFeedback toMsg(const trajectory::GoalFeedback& in) {
  serial_robot_driver::FollowJointTrajectoryFeedback feedback;
  feedback.header.stamp = ros::Time::now();  // ROS time, as every stamp; the executor's is steady
  feedback.joint_names = in.joint_names;
  // ros::Duration throws beyond its 32-bit seconds (a goal may last that long).
  feedback.desired.time_from_start = feedback.actual.time_from_start =
      feedback.error.time_from_start =
          ros::Duration(trajectory::messageDuration(in.time_from_start));
  for (const trajectory::JointSample& d : in.desired) {
    feedback.desired.positions.push_back(d.position);
    feedback.desired.velocities.push_back(d.velocity);
    feedback.desired.accelerations.push_back(d.acceleration);
  }
  feedback.actual.positions = in.actual_positions;
  feedback.actual.velocities = in.actual_velocities;
  feedback.error.positions = in.error_positions;
  feedback.error.velocities = in.error_velocities;
  return feedback;
}

void report(TrajectoryServer::GoalHandle& handle, const trajectory::GoalOutcome& outcome) {
  Result result;
  result.error_code = outcome.error_code;
  result.error_string = outcome.error_string;
  switch (outcome.status) {
    case trajectory::GoalStatus::kRejected:
      return handle.setRejected(result, outcome.text);
    case trajectory::GoalStatus::kSucceeded:
      return handle.setSucceeded(result, outcome.text);
    case trajectory::GoalStatus::kCanceled:
      return handle.setCanceled(result, outcome.text);
    case trajectory::GoalStatus::kAborted:
      return handle.setAborted(result, outcome.text);
  }
}

}  // namespace

trajectory::MessageStamp toMessageStamp(const ros::Time& stamp) { return {stamp.sec, stamp.nsec}; }

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
                                   trajectory::TrajectoryExecutor& executor,
                                   core::InputRefusals& refusals)
    : input_refusals_(refusals),
      executor_(executor),
      loop_period_(1.0 / params.loop_rate),
      nh_(nh),
      action_server_(
          nh, "follow_joint_trajectory", input_refusals_,
          [this](GoalHandle handle) { onGoalGuarded(handle); },
          [this](GoalHandle handle) {
            runGuarded(input_refusals_, "follow_joint_trajectory (cancel)",
                       [&] { executor_.cancelGoal(handle.getGoalID().id); });
          }) {}

TrajectoryServer::~TrajectoryServer() { shutdown(); }

void TrajectoryServer::start() {
  // Steady: a step of the ROS or wall clock must not skip or replay a trajectory. Started while
  // the executor has work (its ticker, under its lock), so an idle node wakes no thread for it.
  timer_ = nh_.createSteadyTimer(
      ros::WallDuration(loop_period_),
      [this](const ros::SteadyTimerEvent&) {
        runGuarded(input_refusals_, "trajectory loop", [this] { executor_.tick(); });
      },
      false, false);
  executor_.setTicker([this](bool on) { on ? timer_.start() : timer_.stop(); });
  if (!executor_.start()) return;
  action_server_.start();
  // tcpNoDelay: a trajectory must not wait in Nagle's buffer.
  trajectory_sub_ =
      subscribeGuarded(nh_, input_refusals_, "joint_trajectory", 10,
                       &TrajectoryServer::onTrajectory, this, ros::TransportHints().tcpNoDelay());
}

void TrajectoryServer::shutdown() {
  // The executor first: once it is shut down its ticker is never switched again.
  executor_.shutdown();
  timer_.stop();
  executor_.setTicker({});  // the executor outlives this server
  trajectory_sub_.shutdown();
}

trajectory::TrajectoryExecutor::Warn TrajectoryServer::logWarning() {
  return [](const std::string& text) { ROS_WARN("%s", text.c_str()); };
}

std::optional<double> TrajectoryServer::startOf(const ros::Time& stamp) const {
  if (stamp.isZero()) return std::nullopt;
  return trajectory::steadyStart(toMessageStamp(stamp), executor_.now(),
                                 toMessageStamp(ros::Time::now()));
}

void TrajectoryServer::onGoalGuarded(GoalHandle handle) {
  std::string error;
  if (runGuarded(
          input_refusals_, "follow_joint_trajectory", [&] { onGoal(handle); }, &error)) {
    return;
  }
  // The goal must still be answered, or its client waits forever.
  runGuarded(input_refusals_, "follow_joint_trajectory", [&] {
    const uint8_t status = handle.getGoalStatus().status;
    trajectory::GoalPhase phase = trajectory::GoalPhase::kOver;
    if (status == actionlib_msgs::GoalStatus::PENDING ||
        status == actionlib_msgs::GoalStatus::RECALLING) {
      phase = trajectory::GoalPhase::kPending;
    } else if (status == actionlib_msgs::GoalStatus::ACTIVE ||
               status == actionlib_msgs::GoalStatus::PREEMPTING) {
      phase = trajectory::GoalPhase::kActive;
    }
    if (const auto outcome = trajectory::internalErrorOutcome(phase, error))
      report(handle, *outcome);
  });
}

void TrajectoryServer::onGoal(GoalHandle handle) {
  const auto goal = handle.getGoal();
  trajectory::Goal converted;
  converted.id = handle.getGoalID().id;
  converted.command = toTrajectoryCommand(goal->trajectory);
  converted.start_time = startOf(goal->trajectory.header.stamp);
  converted.path_tolerance = fromMsg(goal->path_tolerance);
  converted.goal_tolerance = fromMsg(goal->goal_tolerance);
  converted.goal_time_tolerance = goal->goal_time_tolerance.toSec();
  trajectory::GoalCallbacks callbacks;
  callbacks.accepted = [handle]() mutable { handle.setAccepted(); };
  callbacks.feedback = [handle](const trajectory::GoalFeedback& feedback) mutable {
    handle.publishFeedback(toMsg(feedback));
  };
  callbacks.finished = [handle](const trajectory::GoalOutcome& outcome) mutable {
    report(handle, outcome);
  };
  if (executor_.submitGoal(converted, std::move(callbacks)) == Submission::kInvalid) {
    input_refusals_.refused("follow_joint_trajectory");
  }
}

void TrajectoryServer::onTrajectory(const trajectory_msgs::JointTrajectory::ConstPtr& msg) {
  if (executor_.submitTrajectory(toTrajectoryCommand(*msg), startOf(msg->header.stamp)) ==
      Submission::kInvalid) {
    input_refusals_.refused("joint_trajectory");
  }
}

}  // namespace serial_robot_driver::ros_layer
