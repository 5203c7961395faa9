#include "serial_robot_driver/dds/endpoint.h"

#include <stdexcept>

#include "serial_robot_driver/dds/type_description.h"

namespace serial_robot_driver {
namespace dds {

dds_qos_t* createEndpointQos(int depth, const std::string& type_hash) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, kMaxPublishBlocking);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_liveliness(qos, DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  // As rmw_cyclonedds: unregistering a writer's instance does not dispose it.
  dds_qset_writer_data_lifecycle(qos, false);
  const std::string user_data = typeHashUserData(type_hash);
  dds_qset_userdata(qos, user_data.data(), user_data.size());
  return qos;
}

Endpoint::Endpoint(Participant& participant, const dds_topic_descriptor_t& type,
                   const char* ros_type_name, const std::string& name, int depth, Kind kind)
    : participant_(participant), topic_name_(participant.topicName(name)) {
  topic_ = dds_create_topic(participant.handle(), &type, topic_name_.c_str(), nullptr, nullptr);
  if (topic_ < 0) {
    throw std::runtime_error("DDS topic " + topic_name_ + ": " + dds_strretcode(topic_));
  }
  dds_qos_t* qos =
      createEndpointQos(depth > 0 ? depth : defaultHistoryDepth(name), typeHash(ros_type_name));
  entity_ = kind == Kind::kWriter ? dds_create_writer(participant.handle(), topic_, qos, nullptr)
                                  : dds_create_reader(participant.handle(), topic_, qos, nullptr);
  dds_delete_qos(qos);
  if (entity_ < 0) {
    dds_delete(topic_);
    throw std::runtime_error("DDS endpoint on " + topic_name_ + ": " + dds_strretcode(entity_));
  }
  gid_ = entityGid(entity_);
  participant_.discoveryInfo().addEndpoint(
      gid_, kind == Kind::kWriter ? DiscoveryInfo::Kind::kWriter : DiscoveryInfo::Kind::kReader);
}

Endpoint::~Endpoint() {
  participant_.discoveryInfo().removeEndpoint(gid_);
  dds_delete(entity_);
  dds_delete(topic_);
}

}  // namespace dds
}  // namespace serial_robot_driver
