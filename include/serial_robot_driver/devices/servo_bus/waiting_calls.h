// How many calls wait in a queue (queued, not started yet): what the stop services' queue tells
// ServoTransactions::setStopCallsQueued, so that a motion wait gives way to a stop queued behind it
// (the ROS front end's StopCallQueue holds one ticket per queued call).
//
// Threading: any thread. any() reads an atomic count, so it may be asked under another lock; one
// thread at a time uses a ticket (the queue's thread that calls or drops its call).
#pragma once

#include <atomic>
#include <memory>

namespace serial_robot_driver::devices::servo_bus {

class WaitingCalls {
 public:
  /// One queued call's place in the count: it waits from the ticket's making until started() or
  /// the ticket's end (dropped unstarted), and again from requeued() (the queue keeps it to try
  /// again) on. It may outlive the WaitingCalls (a queue destroys its calls last).
  class Ticket {
   public:
    explicit Ticket(std::shared_ptr<std::atomic<int>> count);
    ~Ticket() { started(); }
    Ticket(const Ticket&) = delete;
    Ticket& operator=(const Ticket&) = delete;
    /// The call starts: it no longer waits (a motion wait of this very call must not give way to
    /// itself). Idempotent.
    void started();
    /// The call is back in the queue: it waits again. Idempotent.
    void requeued();

   private:
    const std::shared_ptr<std::atomic<int>> count_;
    bool waiting_ = true;
  };

  /// The ticket of a call queued now.
  Ticket queued() const { return Ticket(count_); }
  /// Whether a call waits.
  bool any() const { return count_->load() > 0; }

 private:
  std::shared_ptr<std::atomic<int>> count_ = std::make_shared<std::atomic<int>>(0);
};

}  // namespace serial_robot_driver::devices::servo_bus
