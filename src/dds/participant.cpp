#include "serial_robot_driver/dds/participant.h"

#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace serial_robot_driver {
namespace dds {

namespace {

dds_entity_t createParticipant(int domain_id) {
  dds_qos_t* qos = dds_create_qos();
  const std::string user_data = enclaveUserData();
  dds_qset_userdata(qos, user_data.data(), user_data.size());
  const dds_entity_t participant = dds_create_participant(domain_id, qos, nullptr);
  dds_delete_qos(qos);
  if (participant < 0) {
    throw std::runtime_error("cannot create the DDS participant on domain " +
                             std::to_string(domain_id) + ": " + dds_strretcode(participant));
  }
  return participant;
}

}  // namespace

Gid entityGid(dds_entity_t entity) {
  dds_guid_t guid{};
  dds_get_guid(entity, &guid);
  Gid gid{};
  static_assert(sizeof(guid.v) == gid.size(), "a DDS GUID is 16 bytes");
  std::memcpy(gid.data(), guid.v, gid.size());
  return gid;
}

Participant::Participant(const NodeOptions& options)
    : domain_id_(resolveDomainId(options.domain_id, std::getenv("ROS_DOMAIN_ID"))),
      node_name_(options.name),
      node_namespace_(normalizedNamespace(options.node_namespace)),
      domain_(domain_id_, discoveryConfigXml(options.peers)) {
  participant_ = createParticipant(domain_id_);
  try {
    gid_ = entityGid(participant_);
    discovery_info_ =
        std::make_unique<DiscoveryInfo>(participant_, gid_, node_name_, node_namespace_);
    dispatch_thread_ = std::make_unique<DispatchThread>(participant_);
  } catch (...) {
    dds_delete(participant_);
    throw;
  }
}

Participant::~Participant() {
  // Callbacks stop before the entities they use go.
  dispatch_thread_.reset();
  discovery_info_.reset();
  dds_delete(participant_);
}

std::string Participant::topicName(const std::string& name) const {
  return ros2TopicName(node_namespace_, name);
}

}  // namespace dds
}  // namespace serial_robot_driver
