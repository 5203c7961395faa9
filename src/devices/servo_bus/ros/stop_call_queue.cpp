#include "serial_robot_driver/devices/servo_bus/ros/stop_call_queue.h"

#include <boost/make_shared.hpp>
#include <utility>

namespace serial_robot_driver::devices::servo_bus::ros {

namespace {

/// A queued call with its ticket in the queue's count of waiting calls.
class CountedCall : public ::ros::CallbackInterface {
 public:
  CountedCall(::ros::CallbackInterfacePtr call, const WaitingCalls& waiting)
      : call_(std::move(call)), ticket_(waiting.queued()) {}

  CallResult call() override {
    ticket_.started();
    const CallResult result = call_->call();
    if (result == TryAgain) ticket_.requeued();  // the queue keeps it
    return result;
  }
  bool ready() override { return call_->ready(); }

 private:
  const ::ros::CallbackInterfacePtr call_;
  WaitingCalls::Ticket ticket_;
};

}  // namespace

StopCallQueue::StopCallQueue(std::function<void()> on_queued) : on_queued_(std::move(on_queued)) {}

void StopCallQueue::addCallback(const ::ros::CallbackInterfacePtr& callback, uint64_t removal_id) {
  ::ros::CallbackQueue::addCallback(boost::make_shared<CountedCall>(callback, waiting_),
                                    removal_id);
  if (on_queued_) on_queued_();
}

}  // namespace serial_robot_driver::devices::servo_bus::ros
