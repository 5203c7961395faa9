// An independent DDS implementation, Fast DDS (Debian's 2.9: what ROS 2's default rmw builds on),
// discovers the node dds_test_peer (another process) makes with the wrappers: its topic with ROS
// 2's name, type name, type hash and QoS, the participant's enclave, and joint_states samples whose
// bytes are the CDR written here by hand. Loopback only, a domain of its own, unicast peer
// 127.0.0.1.
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dds_test_peer_process.h"
#include "dds_test_support.h"

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
using Bytes = std::vector<uint8_t>;
using dds_test::waitFor;

namespace {

// A type that keeps the serialized bytes as they arrive (encapsulation header included).
class RawBytesType : public fdds::TopicDataType {
 public:
  explicit RawBytesType(const char* dds_type_name) {
    setName(dds_type_name);
    m_typeSize = 64 * 1024;
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, rtps::SerializedPayload_t* payload) override {
    const Bytes& bytes = *static_cast<Bytes*>(data);
    std::memcpy(payload->data, bytes.data(), bytes.size());
    payload->length = static_cast<uint32_t>(bytes.size());
    return true;
  }
  bool deserialize(rtps::SerializedPayload_t* payload, void* data) override {
    static_cast<Bytes*>(data)->assign(payload->data, payload->data + payload->length);
    return true;
  }
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<uint32_t>(static_cast<Bytes*>(data)->size()); };
  }
  void* createData() override { return new Bytes(); }
  void deleteData(void* data) override { delete static_cast<Bytes*>(data); }
  bool getKey(void*, rtps::InstanceHandle_t*, bool) override { return false; }
};

struct SeenWriter {
  std::string type_name;
  std::string user_data;
  fdds::ReliabilityQosPolicyKind reliability = fdds::BEST_EFFORT_RELIABILITY_QOS;
  fdds::DurabilityQosPolicyKind durability = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
};

std::string text(const std::vector<rtps::octet>& data) {
  return std::string(data.begin(), data.end());
}

// What Fast DDS's discovery reports, by topic and by participant.
class DiscoveryRecorder : public fdds::DomainParticipantListener {
 public:
  void on_publisher_discovery(fdds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto& writer = info.info;
    writers_[writer.topicName().to_string()] = {
        writer.typeName().to_string(), text(writer.m_qos.m_userData.data_vec()),
        writer.m_qos.m_reliability.kind, writer.m_qos.m_durability.kind};
  }
  void on_participant_discovery(fdds::DomainParticipant*,
                                rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard<std::mutex> lock(mutex_);
    participant_user_data_.push_back(text(info.info.m_userData.data_vec()));
  }
  bool writer(const std::string& topic, SeenWriter* seen) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto found = writers_.find(topic);
    if (found == writers_.end()) return false;
    *seen = found->second;
    return true;
  }
  bool sawParticipantUserData(const std::string& user_data) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& seen : participant_user_data_) {
      if (seen == user_data) return true;
    }
    return false;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, SeenWriter> writers_;
  std::vector<std::string> participant_user_data_;
};

// dds_test_peer's joint_states, by the CDR rules (test_cdr_golden.cpp): stamp 7 s 8 ns, frame
// "base_link", names "left" "right", positions 0.25 -1.5, no velocity, no effort.
// One row per field, as on the wire.
// clang-format off
const Bytes kPeerJointState = {
    0x00, 0x01, 0x00, 0x00,                                                     // CDR little-endian
    0x07, 0,    0,    0,    0x08, 0,   0,    0,                                 // 0: stamp
    0x0a, 0,    0,    0,    'b',  'a', 's',  'e',  '_', 'l', 'i', 'n', 'k', 0,  // 8: frame_id
    0,    0,                                                                    // 22: pad
    0x02, 0,    0,    0,                                                        // 24: two names
    0x05, 0,    0,    0,    'l',  'e', 'f',  't',  0,   0,   0,   0,            // 28: "left", pad
    0x06, 0,    0,    0,    'r',  'i', 'g',  'h',  't', 0,   0,   0,            // 40: "right", pad
    0x02, 0,    0,    0,                                                        // 52: two positions
    0,    0,    0,    0,    0,    0,   0xd0, 0x3f,                              // 56: 0.25
    0,    0,    0,    0,    0,    0,   0xf8, 0xbf,                              // 64: -1.5
    0,    0,    0,    0,    0,    0,   0,    0};  // 72: no velocity, effort
// clang-format on

class FastDdsPeer : public ::testing::Test {
 protected:
  void SetUp() override {
    const int domain_id = dds_test::privateDomainId(60, 50);
    fdds::DomainParticipantQos qos;
    qos.name("fast_dds_observer");
    // UDP on loopback only, the peer's discovery port reached by unicast.
    qos.transport().use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.push_back("127.0.0.1");
    qos.transport().user_transports.push_back(udp);
    rtps::Locator_t peer;
    rtps::IPLocator::setIPv4(peer, "127.0.0.1");
    qos.wire_protocol().builtin.initialPeersList.push_back(peer);
    participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
        domain_id, qos, &recorder_, fdds::StatusMask::none());
    ASSERT_NE(participant_, nullptr);
    ASSERT_TRUE(peer_.start(domain_id));
  }

  void TearDown() override {
    peer_.stop();
    if (participant_) {
      participant_->delete_contained_entities();
      fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    }
  }

  fdds::DataReader* rawReader(const char* dds_type_name, const char* topic_name) {
    fdds::TypeSupport type(new RawBytesType(dds_type_name));
    type.register_type(participant_);
    fdds::Topic* topic =
        participant_->create_topic(topic_name, dds_type_name, fdds::TOPIC_QOS_DEFAULT);
    fdds::Subscriber* subscriber = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    fdds::DataReaderQos qos = fdds::DATAREADER_QOS_DEFAULT;
    qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
    qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
    return subscriber->create_datareader(topic, qos);
  }

  DiscoveryRecorder recorder_;
  fdds::DomainParticipant* participant_ = nullptr;
  dds_test::PeerProcess peer_;
};

TEST_F(FastDdsPeer, SeesTheTopicByRos2Conventions) {
  SeenWriter seen;
  ASSERT_TRUE(waitFor([&] { return recorder_.writer("rt/dds_test/joint_states", &seen); }));
  EXPECT_EQ(seen.type_name, "sensor_msgs::msg::dds_::JointState_");
  EXPECT_EQ(seen.user_data,
            "typehash=RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e;");
  EXPECT_EQ(seen.reliability, fdds::RELIABLE_RELIABILITY_QOS);
  EXPECT_EQ(seen.durability, fdds::VOLATILE_DURABILITY_QOS);
  EXPECT_TRUE(waitFor([&] { return recorder_.sawParticipantUserData("enclave=/;"); }));
  ASSERT_TRUE(waitFor([&] { return recorder_.writer("ros_discovery_info", &seen); }));
  EXPECT_EQ(seen.type_name, "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
  EXPECT_EQ(seen.durability, fdds::TRANSIENT_LOCAL_DURABILITY_QOS);
}

TEST_F(FastDdsPeer, ReceivesTheGoldenJointStateBytes) {
  fdds::DataReader* reader =
      rawReader("sensor_msgs::msg::dds_::JointState_", "rt/dds_test/joint_states");
  ASSERT_NE(reader, nullptr);
  Bytes received;
  fdds::SampleInfo info;
  ASSERT_TRUE(waitFor([&] {
    return reader->take_next_sample(&received, &info) == ReturnCode_t::RETCODE_OK &&
           info.valid_data;
  }));
  EXPECT_EQ(received, kPeerJointState);
}

}  // namespace
