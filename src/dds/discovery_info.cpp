#include "serial_robot_driver/dds/discovery_info.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "serial_robot_driver/dds/c_types.h"
#include "serial_robot_driver/dds/messages.h"
#include "serial_robot_driver/dds/type_description.h"

namespace serial_robot_driver {
namespace dds {

namespace {

using ParticipantEntitiesInfo = rmw_dds_common_msg_dds__ParticipantEntitiesInfo_;
using NodeEntitiesInfo = rmw_dds_common_msg_dds__NodeEntitiesInfo_;
using GidMessage = rmw_dds_common_msg_dds__Gid_;

// The QoS rmw_cyclonedds gives its ros_discovery_info writer.
std::unique_ptr<dds_qos_t, void (*)(dds_qos_t*)> discoveryWriterQos() {
  std::unique_ptr<dds_qos_t, void (*)(dds_qos_t*)> qos(dds_create_qos(), dds_delete_qos);
  dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, 1);
  dds_qset_durability(qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_durability_service(qos.get(), 0, DDS_HISTORY_KEEP_LAST, 1, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  dds_qset_writer_data_lifecycle(qos.get(), false);
  dds_qset_liveliness(qos.get(), DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  const std::string user_data =
      typeHashUserData(typeHash(Message<ParticipantEntitiesInfo>::kRosName));
  dds_qset_userdata(qos.get(), user_data.data(), user_data.size());
  return qos;
}

std::vector<GidMessage> gidMessages(const std::vector<Gid>& gids) {
  std::vector<GidMessage> messages(gids.size());
  for (size_t i = 0; i < gids.size(); ++i) {
    std::memcpy(messages[i].data, gids[i].data(), gids[i].size());
  }
  return messages;
}

// node_name and node_namespace are string<=256: fixed char arrays in the generated struct.
void copyBounded(char (&field)[257], const std::string& text) {
  const size_t length = std::min(text.size(), sizeof(field) - 1);
  std::memcpy(field, text.data(), length);
  field[length] = '\0';
}

}  // namespace

DiscoveryInfo::DiscoveryInfo(dds_entity_t participant, const Gid& participant_gid,
                             std::string node_name, std::string node_namespace)
    : participant_gid_(participant_gid),
      node_name_(std::move(node_name)),
      node_namespace_(std::move(node_namespace)) {
  const dds_entity_t topic =
      dds_create_topic(participant, &Message<ParticipantEntitiesInfo>::descriptor(),
                       kDiscoveryInfoTopic, nullptr, nullptr);
  if (topic < 0)
    throw std::runtime_error("ros_discovery_info topic: " + std::string(dds_strretcode(topic)));
  writer_ = dds_create_writer(participant, topic, discoveryWriterQos().get(), nullptr);
  if (writer_ < 0) {
    throw std::runtime_error("ros_discovery_info writer: " + std::string(dds_strretcode(writer_)));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  publishLocked();
}

DiscoveryInfo::~DiscoveryInfo() { dds_delete(writer_); }

void DiscoveryInfo::addEndpoint(const Gid& gid, Kind kind) {
  std::lock_guard<std::mutex> lock(mutex_);
  (kind == Kind::kReader ? readers_ : writers_).push_back(gid);
  publishLocked();
}

void DiscoveryInfo::removeEndpoint(const Gid& gid) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto* gids : {&readers_, &writers_}) {
    gids->erase(std::remove(gids->begin(), gids->end(), gid), gids->end());
  }
  publishLocked();
}

void DiscoveryInfo::publishLocked() {
  std::vector<GidMessage> readers = gidMessages(readers_);
  std::vector<GidMessage> writers = gidMessages(writers_);
  std::vector<NodeEntitiesInfo> nodes(1);
  copyBounded(nodes[0].node_namespace, node_namespace_);
  copyBounded(nodes[0].node_name, node_name_);
  lend(nodes[0].reader_gid_seq, readers);
  lend(nodes[0].writer_gid_seq, writers);
  ParticipantEntitiesInfo info{};
  std::memcpy(info.gid.data, participant_gid_.data(), participant_gid_.size());
  lend(info.node_entities_info_seq, nodes);
  // A failed write leaves the previous entry in the graph; the next change writes it all again.
  dds_write(writer_, &info);
}

}  // namespace dds
}  // namespace serial_robot_driver
