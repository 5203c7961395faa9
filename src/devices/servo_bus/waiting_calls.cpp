#include "serial_robot_driver/devices/servo_bus/waiting_calls.h"

#include <utility>

namespace serial_robot_driver::devices::servo_bus {

WaitingCalls::Ticket::Ticket(std::shared_ptr<std::atomic<int>> count) : count_(std::move(count)) {
  count_->fetch_add(1);
}

void WaitingCalls::Ticket::started() {
  if (waiting_) count_->fetch_sub(1);
  waiting_ = false;
}

void WaitingCalls::Ticket::requeued() {
  if (!waiting_) count_->fetch_add(1);
  waiting_ = true;
}

}  // namespace serial_robot_driver::devices::servo_bus
