// Threads that serve a ROS callback queue, like ros::AsyncSpinner, but an idle thread sleeps until
// a callback is queued instead of waking every 100 ms (AsyncSpinner's fixed wait): on a node that
// is idle most of the time those wake-ups are a visible share of its CPU.
//
// Threading model: `threads` threads each call queue->callAvailable(); a callback added to the
// queue wakes one of them. stop() disables the queue (which wakes every waiting thread) and joins
// them, so the queue serves no callback after stop(); it is meant for shutdown.
#pragma once

#include <ros/callback_queue.h>
#include <ros/init.h>

#include <atomic>
#include <thread>
#include <vector>

namespace serial_robot_driver::ros_layer {

class QueueSpinner {
 public:
  /// `realtime_priority` > 0: the threads run SCHED_FIFO at it (core/realtime.h), where allowed.
  QueueSpinner(ros::CallbackQueue* queue, int threads, int realtime_priority = 0);
  ~QueueSpinner();
  QueueSpinner(const QueueSpinner&) = delete;
  QueueSpinner& operator=(const QueueSpinner&) = delete;

  void start();
  /// Idempotent. Must not be called from one of the spinner's own callbacks.
  void stop();

 private:
  ros::CallbackQueue* queue_;
  int thread_count_;
  int realtime_priority_;
  std::atomic<bool> stopping_{false};
  std::vector<std::thread> threads_;
};

}  // namespace serial_robot_driver::ros_layer
