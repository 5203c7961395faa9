#pragma once
// A ROS 2 subscription to T (a generated type, messages.h) on DDS. The callback runs on the
// participant's dispatch thread (dispatch_thread.h): one callback at a time across the
// participant, never on Cyclone's threads; it must not block, and gets a sample that is valid
// during the call only (copy out what you keep: c_types.h). A callback that throws is counted
// (DispatchThread::handlerFailures) and the next sample is delivered as usual.

#include <functional>
#include <string>

#include "serial_robot_driver/dds/endpoint.h"
#include "serial_robot_driver/dds/messages.h"

namespace serial_robot_driver {
namespace dds {

template <typename T>
class Subscription {
 public:
  using Callback = std::function<void(const T&)>;

  Subscription(Participant& participant, const std::string& name, Callback callback, int depth = 0)
      : participant_(participant),
        endpoint_(participant, Message<T>::descriptor(), Message<T>::kRosName, name, depth,
                  Endpoint::Kind::kReader),
        callback_(std::move(callback)) {
    participant_.dispatchThread().attach(endpoint_.handle(), [this] { takeAll(); });
  }
  /// After it returns the callback is not running and is never called again. Not from a callback.
  ~Subscription() { participant_.dispatchThread().detach(endpoint_.handle()); }
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;

  /// The DDS writer/reader, for DDS calls the wrapper does not offer (statuses, QoS).
  dds_entity_t handle() const { return endpoint_.handle(); }
  const Gid& gid() const { return endpoint_.gid(); }
  const std::string& topicName() const { return endpoint_.topicName(); }

 private:
  static constexpr size_t kBatch = 16;

  void takeAll() {
    void* samples[kBatch] = {nullptr};
    dds_sample_info_t infos[kBatch];
    dds_return_t count;
    while ((count = dds_take(endpoint_.handle(), samples, infos, kBatch, kBatch)) > 0) {
      // The loan goes back even when a callback throws.
      struct Loan {
        dds_entity_t reader;
        void** samples;
        dds_return_t count;
        ~Loan() {
          dds_return_loan(reader, samples, count);
          samples[0] = nullptr;  // the next take lends again
        }
      } loan{endpoint_.handle(), samples, count};
      for (dds_return_t i = 0; i < count; ++i) {
        if (infos[i].valid_data) callback_(*static_cast<const T*>(samples[i]));
      }
    }
  }

  Participant& participant_;
  Endpoint endpoint_;
  Callback callback_;
};

}  // namespace dds
}  // namespace serial_robot_driver
