#include "serial_robot_driver/ros/queue_spinner.h"

#include "serial_robot_driver/core/realtime.h"

namespace serial_robot_driver::ros_layer {

namespace {
/// Upper bound of one idle wait: callbacks and stop() wake the threads at once, so this only
/// matters if a wake-up were ever missed.
const ros::WallDuration kIdleWait(5.0);
}  // namespace

QueueSpinner::QueueSpinner(ros::CallbackQueue* queue, int threads, int realtime_priority)
    : queue_(queue), thread_count_(threads), realtime_priority_(realtime_priority) {}

QueueSpinner::~QueueSpinner() { stop(); }

void QueueSpinner::start() {
  if (!threads_.empty() || stopping_) return;
  for (int i = 0; i < thread_count_; ++i) {
    threads_.emplace_back([this] {
      core::enterRealtime(realtime_priority_);  // refused: it spins at the normal policy
      while (!stopping_ && ros::ok()) queue_->callAvailable(kIdleWait);
    });
  }
}

void QueueSpinner::stop() {
  if (stopping_.exchange(true)) return;
  queue_->disable();  // wakes the threads waiting in callAvailable()
  for (std::thread& thread : threads_) thread.join();
}

}  // namespace serial_robot_driver::ros_layer
