#include "serial_robot_driver/core/capture_queue.h"

#include <utility>

namespace serial_robot_driver::core {

CaptureQueue::CaptureQueue(CaptureQueueLimits limits) : limits_(limits) {
  thread_ = std::thread([this] { publishLoop(); });
}

CaptureQueue::~CaptureQueue() { stop(); }

void CaptureQueue::stop() {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    stopping_ = true;
  }
  shared_->wake.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool CaptureQueue::push(Publication publication) {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (stopping_ || queue_.size() >= limits_.max_queued) {
      ++stats_.dropped;
      return false;
    }
    queue_.push_back(std::move(publication));
  }
  shared_->wake.notify_all();
  return true;
}

std::shared_ptr<void> CaptureQueue::holdInFlight() {
  const std::shared_ptr<Shared> shared = shared_;
  {
    std::lock_guard<std::mutex> lock(shared->mutex);
    ++shared->in_flight;
  }
  return std::shared_ptr<void>(nullptr, [shared](void*) {
    {
      std::lock_guard<std::mutex> lock(shared->mutex);
      --shared->in_flight;
    }
    shared->wake.notify_all();
  });
}

void CaptureQueue::publishLoop() {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  while (true) {
    shared_->wake.wait(lock, [this] {
      return stopping_ || (!queue_.empty() && shared_->in_flight < limits_.max_in_flight);
    });
    if (queue_.empty()) return;  // stopping, and everything is out
    if (shared_->in_flight >= limits_.max_in_flight) {
      // Stopping while a subscriber keeps the middleware full: waiting for it could last for ever.
      stats_.dropped += queue_.size();
      queue_.clear();
      return;
    }
    Publication publication = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    // Never under the lock: the middleware may release a token on this thread.
    const std::size_t bytes = publication();
    lock.lock();
    ++stats_.chunks;
    stats_.bytes += bytes;
  }
}

WireCaptureStats CaptureQueue::stats() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  WireCaptureStats copy = stats_;
  copy.queued = queue_.size();
  copy.in_roscpp = shared_->in_flight;
  return copy;
}

}  // namespace serial_robot_driver::core
