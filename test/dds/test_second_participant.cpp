// A second DDS participant, in this process and on plain Cyclone (no wrapper of ours), discovers a
// node that dds_test_peer (another process) built with the wrappers, the way a ROS 2 machine
// would: its own domain id, unicast peer 127.0.0.1, multicast off. It sees the topics with ROS 2's
// names, type names, type hashes (USER_DATA) and QoS in the builtin topics, the participant's
// enclave, a joint_states sample with the right values, and the node with its endpoints' GIDs in
// ros_discovery_info. Expected hashes are ROS 2's own (test_type_hash.cpp), not computed here.
#include <gtest/gtest.h>

#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "dds_test_peer_process.h"
#include "dds_test_support.h"
#include "loopback_observer_config.h"
#include "serial_robot_driver/dds/messages.h"

using dds_test::waitFor;

namespace {

const char* kJointStateHash =
    "typehash=RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e;";
const char* kBoolHash =
    "typehash=RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9;";
const char* kDiscoveryInfoHash =
    "typehash=RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e;";

struct DiscoveredEndpoint {
  dds_guid_t guid;
  dds_guid_t participant;
  std::string type_name;
  std::string user_data;
  dds_reliability_kind_t reliability = DDS_RELIABILITY_BEST_EFFORT;
  dds_durability_kind_t durability = DDS_DURABILITY_VOLATILE;
};

std::string userData(const dds_qos_t* qos) {
  void* data = nullptr;
  size_t size = 0;
  if (!qos || !dds_qget_userdata(qos, &data, &size) || !data) return "";
  std::string text(static_cast<const char*>(data), size);
  dds_free(data);
  return text;
}

bool sameGuid(const dds_guid_t& a, const uint8_t (&b)[16]) { return std::memcmp(a.v, b, 16) == 0; }

// Takes every builtin-topic sample of `reader`, keeping the endpoint on `topic_name`.
std::optional<DiscoveredEndpoint> takeEndpoint(dds_entity_t reader, const std::string& topic_name) {
  void* samples[32] = {nullptr};
  dds_sample_info_t infos[32];
  const dds_return_t count = dds_take(reader, samples, infos, 32, 32);
  std::optional<DiscoveredEndpoint> found;
  for (dds_return_t i = 0; i < count; ++i) {
    const auto* endpoint = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
    if (!infos[i].valid_data || topic_name != endpoint->topic_name) continue;
    DiscoveredEndpoint seen{endpoint->key, endpoint->participant_key, endpoint->type_name,
                            userData(endpoint->qos)};
    dds_qget_reliability(endpoint->qos, &seen.reliability, nullptr);
    dds_qget_durability(endpoint->qos, &seen.durability);
    found = seen;
  }
  if (count > 0) dds_return_loan(reader, samples, count);
  return found;
}

class SecondParticipant : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_id_ = dds_test::privateDomainId(175, 50);
    domain_ = dds_create_domain(domain_id_, dds_test::kLoopbackObserverConfig);
    ASSERT_GT(domain_, 0) << dds_strretcode(domain_);
    participant_ = dds_create_participant(domain_id_, nullptr, nullptr);
    ASSERT_GT(participant_, 0);
    ASSERT_TRUE(peer_.start(domain_id_));
  }

  void TearDown() override {
    peer_.stop();
    if (domain_ > 0) dds_delete(domain_);
  }

  std::optional<DiscoveredEndpoint> discover(dds_entity_t builtin_topic, const std::string& name) {
    const dds_entity_t reader = dds_create_reader(participant_, builtin_topic, nullptr, nullptr);
    std::optional<DiscoveredEndpoint> found;
    waitFor([&] { return (found = takeEndpoint(reader, name)).has_value(); });
    dds_delete(reader);
    return found;
  }

  dds_entity_t reliableReader(const dds_topic_descriptor_t& type, const char* topic_name,
                              dds_durability_kind_t durability) {
    const dds_entity_t topic = dds_create_topic(participant_, &type, topic_name, nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
    dds_qset_durability(qos, durability);
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    const dds_entity_t reader = dds_create_reader(participant_, topic, qos, nullptr);
    dds_delete_qos(qos);
    return reader;
  }

  int domain_id_ = 0;
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  dds_test::PeerProcess peer_;
};

TEST_F(SecondParticipant, SeesTopicsTypesHashesAndQos) {
  const auto joint_states = discover(DDS_BUILTIN_TOPIC_DCPSPUBLICATION, "rt/dds_test/joint_states");
  ASSERT_TRUE(joint_states);
  EXPECT_EQ(joint_states->type_name, "sensor_msgs::msg::dds_::JointState_");
  EXPECT_EQ(joint_states->user_data, kJointStateHash);
  EXPECT_EQ(joint_states->reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(joint_states->durability, DDS_DURABILITY_VOLATILE);

  const auto e_stop = discover(DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, "rt/dds_test/e_stop");
  ASSERT_TRUE(e_stop);
  EXPECT_EQ(e_stop->type_name, "std_msgs::msg::dds_::Bool_");
  EXPECT_EQ(e_stop->user_data, kBoolHash);
  EXPECT_EQ(e_stop->reliability, DDS_RELIABILITY_RELIABLE);

  const auto graph = discover(DDS_BUILTIN_TOPIC_DCPSPUBLICATION, "ros_discovery_info");
  ASSERT_TRUE(graph);
  EXPECT_EQ(graph->type_name, "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
  EXPECT_EQ(graph->user_data, kDiscoveryInfoHash);
  EXPECT_EQ(graph->reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(graph->durability, DDS_DURABILITY_TRANSIENT_LOCAL);
}

TEST_F(SecondParticipant, SeesTheParticipantsEnclave) {
  const auto joint_states = discover(DDS_BUILTIN_TOPIC_DCPSPUBLICATION, "rt/dds_test/joint_states");
  ASSERT_TRUE(joint_states);
  const dds_entity_t reader =
      dds_create_reader(participant_, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
  std::string enclave;
  EXPECT_TRUE(waitFor([&] {
    void* samples[32] = {nullptr};
    dds_sample_info_t infos[32];
    const dds_return_t count = dds_read(reader, samples, infos, 32, 32);
    for (dds_return_t i = 0; i < count; ++i) {
      const auto* participant = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
      if (infos[i].valid_data &&
          std::memcmp(participant->key.v, joint_states->participant.v, 16) == 0) {
        enclave = userData(participant->qos);
      }
    }
    if (count > 0) dds_return_loan(reader, samples, count);
    return !enclave.empty();
  }));
  EXPECT_EQ(enclave, "enclave=/;");
}

TEST_F(SecondParticipant, ReceivesJointStatesWithTheirValues) {
  const dds_entity_t reader = reliableReader(sensor_msgs_msg_dds__JointState__desc,
                                             "rt/dds_test/joint_states", DDS_DURABILITY_VOLATILE);
  ASSERT_GT(reader, 0);
  void* samples[1] = {nullptr};
  dds_sample_info_t info;
  ASSERT_TRUE(
      waitFor([&] { return dds_take(reader, samples, &info, 1, 1) == 1 && info.valid_data; }));
  const auto* state = static_cast<const sensor_msgs_msg_dds__JointState_*>(samples[0]);
  EXPECT_EQ(state->header.stamp.sec, 7);
  EXPECT_EQ(state->header.stamp.nanosec, 8u);
  EXPECT_STREQ(state->header.frame_id, "base_link");
  ASSERT_EQ(state->name._length, 2u);
  EXPECT_STREQ(state->name._buffer[0], "left");
  EXPECT_STREQ(state->name._buffer[1], "right");
  ASSERT_EQ(state->position._length, 2u);
  EXPECT_EQ(state->position._buffer[0], 0.25);
  EXPECT_EQ(state->position._buffer[1], -1.5);
  EXPECT_EQ(state->velocity._length, 0u);
  dds_return_loan(reader, samples, 1);
}

// The node as `ros2 node list` finds it: the participant's GID, name and namespace, and the GIDs
// of its writer (joint_states) and reader (e_stop) as the builtin topics give them.
TEST_F(SecondParticipant, ReadsTheNodeInRosDiscoveryInfo) {
  const auto joint_states = discover(DDS_BUILTIN_TOPIC_DCPSPUBLICATION, "rt/dds_test/joint_states");
  const auto e_stop = discover(DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, "rt/dds_test/e_stop");
  ASSERT_TRUE(joint_states && e_stop);
  const dds_entity_t reader = reliableReader(rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                             "ros_discovery_info", DDS_DURABILITY_TRANSIENT_LOCAL);
  ASSERT_GT(reader, 0);
  auto describesTheNode = [&](const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_& info) {
    if (!sameGuid(joint_states->participant, info.gid.data) ||
        info.node_entities_info_seq._length != 1) {
      return false;
    }
    const auto& node = info.node_entities_info_seq._buffer[0];
    return std::string(node.node_name) == "dds_test_peer" &&
           std::string(node.node_namespace) == "/dds_test" && node.writer_gid_seq._length == 1 &&
           sameGuid(joint_states->guid, node.writer_gid_seq._buffer[0].data) &&
           node.reader_gid_seq._length == 1 &&
           sameGuid(e_stop->guid, node.reader_gid_seq._buffer[0].data);
  };
  EXPECT_TRUE(waitFor([&] {
    void* samples[8] = {nullptr};
    dds_sample_info_t infos[8];
    const dds_return_t count = dds_take(reader, samples, infos, 8, 8);
    bool found = false;
    for (dds_return_t i = 0; i < count; ++i) {
      found =
          found ||
          (infos[i].valid_data &&
           describesTheNode(
               *static_cast<const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_*>(samples[i])));
    }
    if (count > 0) dds_return_loan(reader, samples, count);
    return found;
  }));
}

}  // namespace
