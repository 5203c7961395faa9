// The typed wrappers within one process (one participant, its own domain, loopback peers):
// delivery, the dispatch thread, failing callbacks, matching, and the bytes Cyclone actually sends
// for a sample equal to the golden CDR path (cdr.h).
#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "cdr_golden_support.h"
#include "dds_test_support.h"
#include "serial_robot_driver/dds/c_types.h"
#include "serial_robot_driver/dds/cdr.h"
#include "serial_robot_driver/dds/publisher.h"
#include "serial_robot_driver/dds/subscription.h"

namespace dds = serial_robot_driver::dds;
using dds_test::Mailbox;
using dds_test::waitFor;

namespace {

dds::NodeOptions loopbackNode(const std::string& name) {
  dds::NodeOptions options;
  options.name = name;
  options.node_namespace = "/loopback_test";
  options.domain_id = dds_test::privateDomainId(120, 50);
  options.peers = {"127.0.0.1"};
  return options;
}

TEST(DdsLoopback, SubscriptionReceivesOnTheDispatchThread) {
  dds::Participant participant(loopbackNode("loopback_node"));
  Mailbox<bool> received;
  Mailbox<std::thread::id> callback_threads;
  dds::Subscription<std_msgs_msg_dds__Bool_> subscription(
      participant, "e_stop", [&](const std_msgs_msg_dds__Bool_& message) {
        callback_threads.put(std::this_thread::get_id());
        received.put(message.data);
      });
  dds::Publisher<std_msgs_msg_dds__Bool_> publisher(participant, "e_stop");
  ASSERT_TRUE(waitFor([&] { return publisher.hasSubscribers(); }));
  EXPECT_EQ(publisher.topicName(), "rt/loopback_test/e_stop");

  std_msgs_msg_dds__Bool_ stop{true};
  ASSERT_TRUE(publisher.publish(stop));
  ASSERT_TRUE(received.waitForCount(1));
  EXPECT_TRUE(received.values().front());
  EXPECT_NE(callback_threads.values().front(), std::this_thread::get_id());
}

TEST(DdsLoopback, ThrowingCallbackIsCountedAndTheNextSampleArrives) {
  dds::Participant participant(loopbackNode("throwing_node"));
  Mailbox<double> received;
  dds::Subscription<geometry_msgs_msg_dds__Twist_> subscription(
      participant, "cmd_vel", [&](const geometry_msgs_msg_dds__Twist_& twist) {
        if (twist.linear.x < 0) throw std::runtime_error("refused by the test");
        received.put(twist.linear.x);
      });
  dds::Publisher<geometry_msgs_msg_dds__Twist_> publisher(participant, "cmd_vel");
  ASSERT_TRUE(waitFor([&] { return publisher.hasSubscribers(); }));
  geometry_msgs_msg_dds__Twist_ twist{};
  twist.linear.x = -1.0;
  ASSERT_TRUE(publisher.publish(twist));
  ASSERT_TRUE(waitFor([&] { return participant.dispatchThread().handlerFailures() == 1; }));
  twist.linear.x = 0.5;
  ASSERT_TRUE(publisher.publish(twist));
  ASSERT_TRUE(received.waitForCount(1));
  EXPECT_EQ(received.values().front(), 0.5);
}

TEST(DdsLoopback, NoSubscriberNoMatch) {
  dds::Participant participant(loopbackNode("lonely_node"));
  dds::Publisher<sensor_msgs_msg_dds__Imu_> publisher(participant, "imu/data");
  EXPECT_FALSE(publisher.hasSubscribers());
}

struct EndpointQos {
  dds_history_kind_t history = DDS_HISTORY_KEEP_ALL;
  int32_t depth = 0;
  dds_reliability_kind_t reliability = DDS_RELIABILITY_BEST_EFFORT;
  dds_durability_kind_t durability = DDS_DURABILITY_TRANSIENT_LOCAL;
};

EndpointQos qosOf(dds_entity_t endpoint) {
  EndpointQos found;
  dds_qos_t* qos = dds_create_qos();
  dds_get_qos(endpoint, qos);
  dds_qget_history(qos, &found.history, &found.depth);
  dds_qget_reliability(qos, &found.reliability, nullptr);
  dds_qget_durability(qos, &found.durability);
  dds_delete_qos(qos);
  return found;
}

// rclcpp's default QoS; tf keeps 100 (the history depth is not in DDS discovery data, so it is
// checked on the entities themselves).
TEST(DdsLoopback, EndpointsHaveRos2DefaultQos) {
  dds::Participant participant(loopbackNode("qos_node"));
  dds::Publisher<tf2_msgs_msg_dds__TFMessage_> tf(participant, "/tf");
  dds::Publisher<sensor_msgs_msg_dds__JointState_> joint_states(participant, "joint_states");
  dds::Subscription<geometry_msgs_msg_dds__Twist_> cmd_vel(
      participant, "cmd_vel", [](const geometry_msgs_msg_dds__Twist_&) {});
  EXPECT_EQ(tf.topicName(), "rt/tf");
  EXPECT_EQ(qosOf(tf.handle()).depth, 100);
  for (dds_entity_t endpoint : {joint_states.handle(), cmd_vel.handle()}) {
    const EndpointQos qos = qosOf(endpoint);
    EXPECT_EQ(qos.history, DDS_HISTORY_KEEP_LAST);
    EXPECT_EQ(qos.depth, 10);
    EXPECT_EQ(qos.reliability, DDS_RELIABILITY_RELIABLE);
    EXPECT_EQ(qos.durability, DDS_DURABILITY_VOLATILE);
  }
}

// What Cyclone puts on the wire for `sample` written with the wrappers, read back as CDR by a plain
// reader of the same participant.
template <typename T>
std::vector<uint8_t> wireBytes(dds::Participant& participant, const std::string& name,
                               const T& sample) {
  dds::Publisher<T> publisher(participant, name);
  const dds_entity_t topic = dds_create_topic(participant.handle(), &dds::Message<T>::descriptor(),
                                              publisher.topicName().c_str(), nullptr, nullptr);
  const dds_entity_t reader = dds_create_reader(participant.handle(), topic, nullptr, nullptr);
  struct ddsi_serdata* serdata = nullptr;
  dds_sample_info_t info;
  if (reader < 0 || !waitFor([&] { return publisher.hasSubscribers(); }) ||
      !publisher.publish(sample) ||
      !waitFor([&] { return dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE) == 1; })) {
    return {};
  }
  std::vector<uint8_t> wire(ddsi_serdata_size(serdata));
  ddsi_serdata_to_ser(serdata, 0, wire.size(), wire.data());
  ddsi_serdata_unref(serdata);
  dds_delete(reader);
  return wire;
}

TEST(DdsLoopback, WireBytesAreTheGoldenCdr) {
  dds::Participant participant(loopbackNode("wire_node"));
  const cdr_golden::GoldenJointState state;
  const auto wire = wireBytes(participant, "joint_states", state.sample());
  EXPECT_EQ(wire, dds::serializeCdr(dds::Message<sensor_msgs_msg_dds__JointState_>::descriptor(),
                                    &state.sample()));
}

// A payload that is not a multiple of 4 bytes goes out padded, the padding in the options.
TEST(DdsLoopback, ShortPayloadsArePaddedOnTheWire) {
  dds::Participant participant(loopbackNode("padding_node"));
  const auto wire = wireBytes(participant, "e_stop", std_msgs_msg_dds__Bool_{true});
  EXPECT_EQ(wire, (std::vector<uint8_t>{0x00, 0x01, 0x00, 0x03, 0x01, 0x00, 0x00, 0x00}));
  std_msgs_msg_dds__Bool_ decoded{false};
  EXPECT_TRUE(
      dds::deserializeCdr(wire, dds::Message<std_msgs_msg_dds__Bool_>::descriptor(), &decoded));
  EXPECT_TRUE(decoded.data);
}

TEST(DdsLoopback, ADomainKeepsOneDiscoveryConfiguration) {
  dds::Participant first(loopbackNode("first_node"));
  dds::NodeOptions other = loopbackNode("second_node");
  other.peers = {"127.0.0.2"};
  EXPECT_THROW(dds::Participant second(other), std::runtime_error);
  dds::Participant same(loopbackNode("same_node"));  // the same settings share the domain
  EXPECT_NE(same.gid(), first.gid());
}

}  // namespace
