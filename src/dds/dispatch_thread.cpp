#include "serial_robot_driver/dds/dispatch_thread.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace serial_robot_driver {
namespace dds {

namespace {

dds_entity_t checked(dds_entity_t entity, const char* what) {
  if (entity < 0) throw std::runtime_error(std::string(what) + ": " + dds_strretcode(entity));
  return entity;
}

constexpr size_t kMaxTriggeredPerWake = 32;

}  // namespace

DispatchThread::DispatchThread(dds_entity_t participant) {
  waitset_ = checked(dds_create_waitset(participant), "dds_create_waitset");
  stop_condition_ = checked(dds_create_guardcondition(participant), "dds_create_guardcondition");
  dds_waitset_attach(waitset_, stop_condition_, 0);
  thread_ = std::thread([this] { run(); });
}

DispatchThread::~DispatchThread() {
  stopping_ = true;
  dds_set_guardcondition(stop_condition_, true);
  thread_.join();
  dds_delete(waitset_);
  dds_delete(stop_condition_);
}

void DispatchThread::attach(dds_entity_t reader, std::function<void()> on_data) {
  const dds_entity_t condition =
      checked(dds_create_readcondition(reader, DDS_ANY_STATE), "dds_create_readcondition");
  std::lock_guard<std::mutex> lock(handlers_mutex_);
  handlers_[condition] = std::move(on_data);
  conditions_[reader] = condition;
  dds_waitset_attach(waitset_, condition, static_cast<dds_attach_t>(condition));
}

void DispatchThread::detach(dds_entity_t reader) {
  std::lock_guard<std::mutex> lock(handlers_mutex_);
  auto found = conditions_.find(reader);
  if (found == conditions_.end()) return;
  dds_waitset_detach(waitset_, found->second);
  dds_delete(found->second);
  handlers_.erase(found->second);
  conditions_.erase(found);
}

void DispatchThread::run() {
  std::vector<dds_attach_t> triggered(kMaxTriggeredPerWake);
  while (!stopping_) {
    const dds_return_t count =
        dds_waitset_wait(waitset_, triggered.data(), triggered.size(), DDS_INFINITY);
    if (count < 0) break;  // the waitset is gone: nothing left to wait for
    for (dds_return_t i = 0; i < count && !stopping_; ++i) {
      if (triggered[i] != 0) dispatch(triggered[i]);
    }
  }
}

void DispatchThread::dispatch(dds_attach_t condition) {
  std::lock_guard<std::mutex> lock(handlers_mutex_);
  // A reader detached since the wait returned has no handler any more.
  auto found = handlers_.find(static_cast<dds_entity_t>(condition));
  if (found == handlers_.end()) return;
  try {
    found->second();
  } catch (...) {
    ++handler_failures_;
  }
}

}  // namespace dds
}  // namespace serial_robot_driver
