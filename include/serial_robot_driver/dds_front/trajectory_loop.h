// The trajectories' loop where no ROS 1 node runs them (dds_driver): starts the core's executor,
// ticks it at the loop rate on a thread of its own (one sync-write per tick, as driver_node's
// trajectory timer does) and shuts it down. Inside driver_node the ROS trajectory server does this.
#pragma once

#include <condition_variable>
#include <mutex>
#include <thread>

#include "serial_robot_driver/trajectory/executor.h"

namespace serial_robot_driver::dds_front {

class TrajectoryLoop {
 public:
  /// `executor` (null: nothing to run) outlives this; `rate` in Hz (~loop_rate).
  TrajectoryLoop(trajectory::TrajectoryExecutor* executor, double rate);
  ~TrajectoryLoop();
  TrajectoryLoop(const TrajectoryLoop&) = delete;
  TrajectoryLoop& operator=(const TrajectoryLoop&) = delete;

  /// After the devices started: goals and messages are taken from now on.
  void start();
  /// Before the devices shut down: every goal aborted, the ticks stopped. Idempotent.
  void shutdown();

 private:
  void run();

  trajectory::TrajectoryExecutor* executor_;
  const std::chrono::nanoseconds period_;
  std::mutex mutex_;  // guards stopping_
  std::condition_variable stop_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace serial_robot_driver::dds_front
