// A second DDS participant, in this process and on plain Cyclone (no wrapper of ours), discovers a
// node that dds_test_peer (another process) built with the wrappers, the way a ROS 2 machine
// would: its own domain id, unicast peer 127.0.0.1, multicast off. It sees the topics with ROS 2's
// names, type names, type hashes (USER_DATA) and QoS in the builtin topics, the participant's
// enclave, a joint_states sample with the right values, and the node with its endpoints' GIDs in
// ros_discovery_info. Expected hashes are ROS 2's own (test_type_hash.cpp), not computed here.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../dds_front/ros2_peer.h"
#include "dds_test_peer_process.h"
#include "dds_test_support.h"
#include "serial_robot_driver/dds/messages.h"

using dds_test::waitFor;

namespace {

const char* kJointStateHash =
    "typehash=RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e;";
const char* kBoolHash =
    "typehash=RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9;";
const char* kDiscoveryInfoHash =
    "typehash=RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e;";

bool sameGuid(const dds_guid_t& a, const uint8_t (&b)[16]) { return std::memcmp(a.v, b, 16) == 0; }

/// A ROS 2 machine (ros2_peer.h, plain Cyclone) and dds_test_peer, in a domain of their own.
class SecondParticipant : public ::testing::Test {
 protected:
  void SetUp() override {
    const int domain_id = dds_test::privateDomainId(175, 50);
    observer_ = std::make_unique<dds_test::Ros2Peer>(domain_id);
    ASSERT_TRUE(peer_.start(domain_id));
  }

  void TearDown() override {
    peer_.stop();
    observer_.reset();
  }

  std::unique_ptr<dds_test::Ros2Peer> observer_;
  dds_test::PeerProcess peer_;
};

TEST_F(SecondParticipant, SeesTopicsTypesHashesAndQos) {
  const auto joint_states = observer_->discover(true, "rt/dds_test/joint_states");
  ASSERT_TRUE(joint_states);
  EXPECT_EQ(joint_states->type_name, "sensor_msgs::msg::dds_::JointState_");
  EXPECT_EQ(joint_states->user_data, kJointStateHash);
  EXPECT_EQ(joint_states->reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(joint_states->durability, DDS_DURABILITY_VOLATILE);

  const auto e_stop = observer_->discover(false, "rt/dds_test/e_stop");
  ASSERT_TRUE(e_stop);
  EXPECT_EQ(e_stop->type_name, "std_msgs::msg::dds_::Bool_");
  EXPECT_EQ(e_stop->user_data, kBoolHash);
  EXPECT_EQ(e_stop->reliability, DDS_RELIABILITY_RELIABLE);

  const auto graph = observer_->discover(true, "ros_discovery_info");
  ASSERT_TRUE(graph);
  EXPECT_EQ(graph->type_name, "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
  EXPECT_EQ(graph->user_data, kDiscoveryInfoHash);
  EXPECT_EQ(graph->reliability, DDS_RELIABILITY_RELIABLE);
  EXPECT_EQ(graph->durability, DDS_DURABILITY_TRANSIENT_LOCAL);
}

TEST_F(SecondParticipant, SeesTheParticipantsEnclave) {
  const auto joint_states = observer_->discover(true, "rt/dds_test/joint_states");
  ASSERT_TRUE(joint_states);
  const dds_entity_t reader = dds_create_reader(
      observer_->participant(), DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
  std::string enclave;
  EXPECT_TRUE(waitFor([&] {
    void* samples[32] = {nullptr};
    dds_sample_info_t infos[32];
    const dds_return_t count = dds_read(reader, samples, infos, 32, 32);
    for (dds_return_t i = 0; i < count; ++i) {
      const auto* participant = static_cast<const dds_builtintopic_participant_t*>(samples[i]);
      if (infos[i].valid_data &&
          std::memcmp(participant->key.v, joint_states->participant.v, 16) == 0) {
        enclave = dds_test::userData(participant->qos);
      }
    }
    if (count > 0) dds_return_loan(reader, samples, count);
    return !enclave.empty();
  }));
  EXPECT_EQ(enclave, "enclave=/;");
}

TEST_F(SecondParticipant, ReceivesJointStatesWithTheirValues) {
  const dds_entity_t reader =
      observer_->reader(sensor_msgs_msg_dds__JointState__desc, "rt/dds_test/joint_states");
  ASSERT_GT(reader, 0);
  // Copied out: the sample lives only during the call.
  int32_t sec = 0;
  uint32_t nanosec = 0, velocities = 1;
  std::string frame;
  std::vector<std::string> names;
  std::vector<double> positions;
  ASSERT_TRUE(dds_test::waitForSample<sensor_msgs_msg_dds__JointState_>(reader, [&](const auto& s) {
    sec = s.header.stamp.sec;
    nanosec = s.header.stamp.nanosec;
    frame = s.header.frame_id;
    names.assign(s.name._buffer, s.name._buffer + s.name._length);
    positions.assign(s.position._buffer, s.position._buffer + s.position._length);
    velocities = s.velocity._length;
    return true;
  }));
  EXPECT_EQ(sec, 7);
  EXPECT_EQ(nanosec, 8u);
  EXPECT_EQ(frame, "base_link");
  EXPECT_EQ(names, (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(positions, (std::vector<double>{0.25, -1.5}));
  EXPECT_EQ(velocities, 0u);
}

// The node as `ros2 node list` finds it: the participant's GID, name and namespace, and the GIDs
// of its writer (joint_states) and reader (e_stop) as the builtin topics give them.
TEST_F(SecondParticipant, ReadsTheNodeInRosDiscoveryInfo) {
  const auto joint_states = observer_->discover(true, "rt/dds_test/joint_states");
  const auto e_stop = observer_->discover(false, "rt/dds_test/e_stop");
  ASSERT_TRUE(joint_states && e_stop);
  const dds_entity_t reader =
      observer_->reader(rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc, "ros_discovery_info",
                        DDS_DURABILITY_TRANSIENT_LOCAL);
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
  EXPECT_TRUE(dds_test::waitForSample<rmw_dds_common_msg_dds__ParticipantEntitiesInfo_>(
      reader, describesTheNode));
}

}  // namespace
