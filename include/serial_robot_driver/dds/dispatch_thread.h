#pragma once
// The one thread on which a participant's subscription callbacks run.
//
// Threading model: each Participant owns one DispatchThread. It waits (a DDS waitset) on the
// read conditions of every attached reader and calls the reader's handler there, one handler at
// a time, in the order the waitset reports them. Nothing runs on Cyclone's own receive threads, and
// never inside a publish() of this process (Cyclone delivers local samples on the writer's
// thread; a listener would run our callbacks there). Handlers must not block: they delay every
// other subscription of the participant. detach() waits for a handler that is running, so it must
// not be called from a handler.

#include <dds/dds.h>

#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <thread>

namespace serial_robot_driver {
namespace dds {

class DispatchThread {
 public:
  /// Starts the thread (waitset on `participant`). Throws std::runtime_error when DDS fails.
  explicit DispatchThread(dds_entity_t participant);
  /// Stops and joins the thread.
  ~DispatchThread();
  DispatchThread(const DispatchThread&) = delete;
  DispatchThread& operator=(const DispatchThread&) = delete;

  /// Calls `on_data` on the thread whenever `reader` holds samples (it should take them all).
  void attach(dds_entity_t reader, std::function<void()> on_data);
  /// After it returns, the reader's handler is not running and never runs again.
  void detach(dds_entity_t reader);
  /// Handlers that threw (caught here: input never ends the process).
  uint64_t handlerFailures() const { return handler_failures_; }

 private:
  void run();
  void dispatch(dds_attach_t condition);

  dds_entity_t waitset_ = 0;
  dds_entity_t stop_condition_ = 0;
  std::mutex handlers_mutex_;                               // held while a handler runs
  std::map<dds_entity_t, std::function<void()>> handlers_;  // by read condition
  std::map<dds_entity_t, dds_entity_t> conditions_;         // by reader
  std::atomic<bool> stopping_{false};
  std::atomic<uint64_t> handler_failures_{0};
  std::thread thread_;
};

}  // namespace dds
}  // namespace serial_robot_driver
