// actionlib's ActionServer with its inputs checked: the same topics (goal and cancel in; result,
// feedback and status out) and the same goal handling (actionlib::ActionServerBase), but the goal
// and cancel messages reach actionlib through runGuarded() (ros/guarded_callbacks.h), and one
// whose goal_id.stamp actionlib's own time arithmetic cannot take is refused first.
// actionlib::ActionServer subscribes by itself and adds its status_list_timeout to such stamps in
// its status timer: a goal_id stamped near the end of ros::Time's 32-bit seconds (or with an
// unnormalised nsec) threw "Time is out of dual 32-bit range" there and ended the process.
#pragma once

// action_server.h brings what action_server_base.h needs but does not include.
#include <actionlib/server/action_server.h>
#include <actionlib_msgs/GoalStatusArray.h>
#include <ros/ros.h>

#include <cstdint>
#include <string>

#include "serial_robot_driver/ros/guarded_callbacks.h"
#include "serial_robot_driver/trajectory/message_time.h"

namespace serial_robot_driver::ros_layer {

template <class ActionSpec>
class GuardedActionServer : public actionlib::ActionServerBase<ActionSpec> {
 public:
  ACTION_DEFINITION(ActionSpec);
  using GoalHandle = actionlib::ServerGoalHandle<ActionSpec>;
  using Base = actionlib::ActionServerBase<ActionSpec>;

  /// As actionlib::ActionServer(nh, name, goal_cb, cancel_cb, false): start() starts it. Inputs
  /// refused and callback errors are counted in `refusals` under `name`.
  GuardedActionServer(const ros::NodeHandle& nh, const std::string& name,
                      core::InputRefusals& refusals, boost::function<void(GoalHandle)> goal_cb,
                      boost::function<void(GoalHandle)> cancel_cb)
      : Base(goal_cb, cancel_cb, false), node_(nh, name), name_(name), refusals_(refusals) {}

 private:
  static constexpr uint32_t kQueue = 50;             // actionlib's default queue sizes
  static constexpr double kStatusPeriod = 0.2;       // s: actionlib's default 5 Hz status
  static constexpr double kStatusListTimeout = 5.0;  // s: actionlib's default

  void initialize() override {
    result_pub_ = node_.advertise<ActionResult>("result", kQueue);
    feedback_pub_ = node_.advertise<ActionFeedback>("feedback", kQueue);
    status_pub_ = node_.advertise<actionlib_msgs::GoalStatusArray>("status", kQueue, true);
    this->status_list_timeout_ = ros::Duration(kStatusListTimeout);
    status_timer_ = node_.createTimer(ros::Duration(kStatusPeriod), [this](const ros::TimerEvent&) {
      runGuarded(refusals_, name_ + " (status)", [this] {
        boost::recursive_mutex::scoped_lock lock(this->lock_);
        if (this->started_) publishStatus();
      });
    });
    const SubscriberCallback<ActionGoal> on_goal = [this](const ActionGoalConstPtr& goal) {
      if (checkedStamp(goal->goal_id.stamp)) this->goalCallback(goal);
    };
    const SubscriberCallback<actionlib_msgs::GoalID> on_cancel =
        [this](const actionlib_msgs::GoalIDConstPtr& id) {
          if (checkedStamp(id->stamp)) this->cancelCallback(id);
        };
    goal_sub_ =
        node_.subscribe<ActionGoal>("goal", kQueue, guardedSubscriber(refusals_, name_, on_goal));
    cancel_sub_ = node_.subscribe<actionlib_msgs::GoalID>(
        "cancel", kQueue, guardedSubscriber(refusals_, name_ + " (cancel)", on_cancel));
  }

  /// Refuses (logs, counts) a goal_id stamp actionlib cannot compute with.
  bool checkedStamp(const ros::Time& stamp) {
    const trajectory::MessageStamp as_sent{stamp.sec, stamp.nsec};
    if (trajectory::actionTimersCanTake(as_sent)) return true;
    refusals_.refused(name_);
    ROS_WARN_THROTTLE(1.0, "%s", trajectory::unusableStampText(name_, as_sent).c_str());
    return false;
  }

  void publishResult(const actionlib_msgs::GoalStatus& status, const Result& result) override {
    boost::recursive_mutex::scoped_lock lock(this->lock_);
    boost::shared_ptr<ActionResult> message(new ActionResult);
    message->header.stamp = ros::Time::now();
    message->status = status;
    message->result = result;
    result_pub_.publish(message);
    publishStatus();
  }

  void publishFeedback(const actionlib_msgs::GoalStatus& status,
                       const Feedback& feedback) override {
    boost::recursive_mutex::scoped_lock lock(this->lock_);
    boost::shared_ptr<ActionFeedback> message(new ActionFeedback);
    message->header.stamp = ros::Time::now();
    message->status = status;
    message->feedback = feedback;
    feedback_pub_.publish(message);
  }

  /// actionlib's, with the age of a finished goal computed in seconds (never throws).
  void publishStatus() override {
    boost::recursive_mutex::scoped_lock lock(this->lock_);
    actionlib_msgs::GoalStatusArray array;
    const ros::Time now = ros::Time::now();
    array.header.stamp = now;
    for (auto it = this->status_list_.begin(); it != this->status_list_.end();) {
      array.status_list.push_back(it->status_);
      const ros::Time& destruction = it->handle_destruction_time_;
      const double age =
          trajectory::secondsBetween({now.sec, now.nsec}, {destruction.sec, destruction.nsec});
      if (!destruction.isZero() && age > kStatusListTimeout) {
        it = this->status_list_.erase(it);
      } else {
        ++it;
      }
    }
    status_pub_.publish(array);
  }

  ros::NodeHandle node_;
  const std::string name_;
  core::InputRefusals& refusals_;
  ros::Publisher result_pub_, feedback_pub_, status_pub_;
  ros::Subscriber goal_sub_, cancel_sub_;
  ros::Timer status_timer_;
};

}  // namespace serial_robot_driver::ros_layer
