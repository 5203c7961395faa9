// The callback queue of the servo bus's stop services (servo/spin, servo/relax, servo/damping,
// servo/hold; see servo_bus_ros.h): a ros::CallbackQueue that knows whether a call waits in
// it and says when one is queued, so that a motion wait on the thread that serves it (a servo/spin
// with wait: true) gives way to the stop queued behind it
// (device::ServoTransactions::setStopCallsQueued).
//
// Threading: any thread (waiting(): WaitingCalls::any()); `on_queued` runs on the thread that
// queued the call (roscpp's), after the call is in the queue.
#pragma once

#include <ros/callback_queue.h>

#include <cstdint>
#include <functional>

#include "serial_robot_driver/devices/servo_bus/waiting_calls.h"

namespace serial_robot_driver::devices::servo_bus::ros {

class StopCallQueue : public ::ros::CallbackQueue {
 public:
  explicit StopCallQueue(std::function<void()> on_queued);

  void addCallback(const ::ros::CallbackInterfacePtr& callback, uint64_t removal_id = 0) override;
  /// Whether a call waits in the queue (queued, not started yet).
  bool waiting() const { return waiting_.any(); }

 private:
  const std::function<void()> on_queued_;
  // The queued calls' tickets outlive it: the base class destroys the calls after our members.
  WaitingCalls waiting_;
};

}  // namespace serial_robot_driver::devices::servo_bus::ros
