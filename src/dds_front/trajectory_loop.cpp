#include "serial_robot_driver/dds_front/trajectory_loop.h"

#include <exception>

#include "serial_robot_driver/core/log.h"

namespace serial_robot_driver::dds_front {

TrajectoryLoop::TrajectoryLoop(trajectory::TrajectoryExecutor* executor, double rate)
    : executor_(executor),
      period_(std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::duration<double>(1.0 / rate))) {}

TrajectoryLoop::~TrajectoryLoop() { shutdown(); }

void TrajectoryLoop::start() {
  if (executor_ == nullptr || !executor_->start()) return;
  thread_ = std::thread([this] { run(); });
}

void TrajectoryLoop::shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  stop_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (executor_ != nullptr) executor_->shutdown();
}

void TrajectoryLoop::run() {
  // Steady deadlines: a step of the wall clock must not skip or replay a trajectory.
  auto next = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_.wait_until(lock, next += period_, [this] { return stopping_; })) {
    lock.unlock();
    try {
      executor_->tick();
    } catch (const std::exception& e) {  // no input may end the process
      core::log(core::LogLevel::kError, "trajectory loop: %s", e.what());
    }
    lock.lock();
  }
}

}  // namespace serial_robot_driver::dds_front
