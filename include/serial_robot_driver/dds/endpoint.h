#pragma once
// What Publisher<T> and Subscription<T> share, without the type: the topic ("rt/..." and ROS 2's
// DDS type name), the reader or writer with ROS 2's default QoS (reliable, volatile, keep-last
// `depth`, USER_DATA "typehash=RIHS01_...;") and its place in ros_discovery_info.

#include <dds/dds.h>

#include <string>

#include "serial_robot_driver/dds/participant.h"

namespace serial_robot_driver {
namespace dds {

class Endpoint {
 public:
  enum class Kind { kReader, kWriter };
  /// `name`: the ROS 2 topic relative to the node's namespace; `depth` 0: defaultHistoryDepth().
  /// Throws std::runtime_error when DDS refuses the topic or the endpoint.
  Endpoint(Participant& participant, const dds_topic_descriptor_t& type, const char* ros_type_name,
           const std::string& name, int depth, Kind kind);
  ~Endpoint();
  Endpoint(const Endpoint&) = delete;
  Endpoint& operator=(const Endpoint&) = delete;

  dds_entity_t handle() const { return entity_; }
  const Gid& gid() const { return gid_; }
  const std::string& topicName() const { return topic_name_; }

 private:
  Participant& participant_;
  std::string topic_name_;
  dds_entity_t topic_ = 0;
  dds_entity_t entity_ = 0;
  Gid gid_{};
};

/// The QoS of a ROS 2 endpoint with rclcpp's defaults and `depth` (the writer waits at most
/// kMaxPublishBlocking for a full history, so a stuck reader never stalls a device thread).
dds_qos_t* createEndpointQos(int depth, const std::string& type_hash);
constexpr dds_duration_t kMaxPublishBlocking = DDS_MSECS(100);

}  // namespace dds
}  // namespace serial_robot_driver
