#include "serial_robot_driver/devices/servo_bus/ros/stop_call_queue.h"

#include <boost/make_shared.hpp>
#include <utility>

namespace serial_robot_driver::devices::servo_bus::ros {

namespace {

/// A queued call, counted as waiting from its queuing until it starts (or is dropped unstarted).
class CountedCall : public ::ros::CallbackInterface {
 public:
  CountedCall(::ros::CallbackInterfacePtr call, std::shared_ptr<std::atomic<int>> waiting)
      : call_(std::move(call)), waiting_(std::move(waiting)) {
    waiting_->fetch_add(1);
  }
  ~CountedCall() override { started(); }
  CountedCall(const CountedCall&) = delete;
  CountedCall& operator=(const CountedCall&) = delete;

  CallResult call() override {
    // Started: a motion wait of this very call must not give way to itself.
    started();
    const CallResult result = call_->call();
    if (result == TryAgain) {  // the queue keeps it: waiting again
      counted_ = true;
      waiting_->fetch_add(1);
    }
    return result;
  }
  bool ready() override { return call_->ready(); }

 private:
  void started() {
    if (counted_) waiting_->fetch_sub(1);
    counted_ = false;
  }

  const ::ros::CallbackInterfacePtr call_;
  const std::shared_ptr<std::atomic<int>> waiting_;
  bool counted_ = true;  // one thread at a time calls or destroys a queued call
};

}  // namespace

StopCallQueue::StopCallQueue(std::function<void()> on_queued) : on_queued_(std::move(on_queued)) {}

void StopCallQueue::addCallback(const ::ros::CallbackInterfacePtr& callback, uint64_t removal_id) {
  ::ros::CallbackQueue::addCallback(boost::make_shared<CountedCall>(callback, waiting_),
                                    removal_id);
  if (on_queued_) on_queued_();
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
