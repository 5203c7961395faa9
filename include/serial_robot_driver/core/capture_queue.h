// The wire capture's queue, without the middleware: the bounded hand-off between the threads that
// move bytes (a port's reader, the base loop, a service thread: push() only queues) and the
// capture's own publishing thread, with every loss counted in one place.
//
// Memory is bounded: a middleware that keeps one outgoing queue per subscriber and silently
// discards the oldest message of a full one (roscpp) cannot count its overflow, so it is never let
// to overflow. The front end holds an in-flight token (holdInFlight()) for each message the
// middleware keeps serialized, released when the middleware lets go of it, and the publishing
// thread hands a new chunk over only while fewer than max_in_flight tokens are alive. A subscriber
// that falls behind thus holds the publishing back; this queue fills, and past max_queued new
// chunks are dropped and counted ("chunks dropped"). The price of one stream for all: a stalled
// subscriber holds back the others too.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>

#include "serial_robot_driver/core/wire_capture_status.h"

namespace serial_robot_driver::core {

struct CaptureQueueLimits {
  /// About 10 s of a busy 1 Mbaud port; a backlog beyond this means the subscribers cannot keep up.
  std::size_t max_queued = 20000;
  /// Published chunks the middleware may hold unsent (its per-subscriber outgoing queues, the
  /// longest one).
  std::size_t max_in_flight = 1000;
};

class CaptureQueue {
 public:
  /// One queued chunk: publishes it when called (on the queue's thread, never under its lock) and
  /// returns its size in bytes.
  using Publication = std::function<std::size_t()>;

  /// Starts the publishing thread.
  explicit CaptureQueue(CaptureQueueLimits limits);
  /// stop().
  ~CaptureQueue();
  CaptureQueue(const CaptureQueue&) = delete;
  CaptureQueue& operator=(const CaptureQueue&) = delete;

  /// Queues `publication` (any thread); false when the queue is full: dropped and counted.
  bool push(Publication publication);
  /// A token for a message the middleware keeps: alive while it holds the message, destroyed when
  /// it lets go (any thread; it may outlive the queue).
  std::shared_ptr<void> holdInFlight();
  /// The counters; `in_roscpp` counts the tokens alive.
  WireCaptureStats stats() const;
  /// Publishes what is still queued while the middleware has room (what it has no room for is
  /// counted as dropped: a stalled subscriber cannot hold the node's exit), then stops the thread.
  /// Nothing is queued afterwards. Idempotent.
  void stop();

 private:
  /// What the tokens report to; shared with them, as the middleware may release one after the
  /// queue is gone.
  struct Shared {
    std::mutex mutex;  // guards the queue, stats and stopping flag as well
    std::condition_variable wake;
    std::size_t in_flight = 0;
  };

  void publishLoop();

  const CaptureQueueLimits limits_;
  const std::shared_ptr<Shared> shared_ = std::make_shared<Shared>();
  std::deque<Publication> queue_;
  bool stopping_ = false;
  WireCaptureStats stats_;
  std::thread thread_;
};

}  // namespace serial_robot_driver::core
