#pragma once
// A ROS 2 publisher of T (a generated type, messages.h) on DDS.

#include <string>

#include "serial_robot_driver/dds/endpoint.h"
#include "serial_robot_driver/dds/messages.h"

namespace serial_robot_driver {
namespace dds {

template <typename T>
class Publisher {
 public:
  /// `name` relative to the node's namespace ("joint_states", "/tf"); `depth` 0: 10, tf 100.
  Publisher(Participant& participant, const std::string& name, int depth = 0)
      : endpoint_(participant, Message<T>::descriptor(), Message<T>::kRosName, name, depth,
                  Endpoint::Kind::kWriter) {}

  /// Serializes and sends `sample` (its pointers need only live until this returns). Thread-safe.
  /// False when DDS refused it; never blocks longer than kMaxPublishBlocking.
  bool publish(const T& sample) { return dds_write(endpoint_.handle(), &sample) == DDS_RETCODE_OK; }

  /// Whether any reader matches now (build nothing for a topic nobody reads).
  bool hasSubscribers() const {
    dds_publication_matched_status_t status{};
    return dds_get_publication_matched_status(endpoint_.handle(), &status) == DDS_RETCODE_OK &&
           status.current_count > 0;
  }

  /// The DDS writer/reader, for DDS calls the wrapper does not offer (statuses, QoS).
  dds_entity_t handle() const { return endpoint_.handle(); }
  const Gid& gid() const { return endpoint_.gid(); }
  const std::string& topicName() const { return endpoint_.topicName(); }

 private:
  Endpoint endpoint_;
};

}  // namespace dds
}  // namespace serial_robot_driver
