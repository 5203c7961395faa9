// The count of stop calls waiting in their queue (WaitingCalls): a call waits from its queuing
// until it starts or is dropped unstarted, and again when the queue keeps it to try again.
#include <gtest/gtest.h>

#include <memory>

#include "serial_robot_driver/devices/servo_bus/waiting_calls.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

TEST(WaitingCalls, ACallWaitsFromItsQueuingUntilItStarts) {
  WaitingCalls waiting;
  EXPECT_FALSE(waiting.any()) << "nothing queued";
  WaitingCalls::Ticket first = waiting.queued();
  WaitingCalls::Ticket second = waiting.queued();
  EXPECT_TRUE(waiting.any());
  first.started();
  EXPECT_TRUE(waiting.any()) << "the second one still waits";
  first.started();  // again: counted once
  EXPECT_TRUE(waiting.any());
  second.started();
  EXPECT_FALSE(waiting.any());
}

TEST(WaitingCalls, ACallDroppedUnstartedWaitsNoLonger) {
  WaitingCalls waiting;
  {
    WaitingCalls::Ticket dropped = waiting.queued();
    EXPECT_TRUE(waiting.any());
  }
  EXPECT_FALSE(waiting.any());
  {
    WaitingCalls::Ticket done = waiting.queued();
    done.started();
  }
  EXPECT_FALSE(waiting.any()) << "a started call's end counts nothing more";
}

TEST(WaitingCalls, ACallTheQueueKeepsWaitsAgain) {
  WaitingCalls waiting;
  WaitingCalls::Ticket ticket = waiting.queued();
  ticket.started();
  ticket.requeued();
  EXPECT_TRUE(waiting.any());
  ticket.requeued();  // again: counted once
  ticket.started();
  EXPECT_FALSE(waiting.any());
  ticket.requeued();
  EXPECT_TRUE(waiting.any());
}

TEST(WaitingCalls, ATicketMayOutliveItsCount) {
  auto waiting = std::make_unique<WaitingCalls>();
  std::unique_ptr<WaitingCalls::Ticket> ticket(new WaitingCalls::Ticket(waiting->queued()));
  waiting.reset();  // a queue destroys its calls after its members
  ticket->started();
  ticket->requeued();
  ticket.reset();
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
