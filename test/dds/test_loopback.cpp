// The typed wrappers within one process (one participant, its own domain, loopback peers):
// delivery, the dispatch thread, failing callbacks, matching, and the bytes Cyclone actually sends
// for a sample equal to the golden CDR path (cdr.h).
#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

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

// What Cyclone puts on the wire for a JointState written with the wrappers: read back as CDR by a
// plain reader of the same participant.
TEST(DdsLoopback, WireBytesAreTheGoldenCdr) {
  dds::Participant participant(loopbackNode("wire_node"));
  dds::Publisher<sensor_msgs_msg_dds__JointState_> publisher(participant, "joint_states");
  const auto& type = dds::Message<sensor_msgs_msg_dds__JointState_>::descriptor();
  const dds_entity_t topic = dds_create_topic(participant.handle(), &type,
                                              "rt/loopback_test/joint_states", nullptr, nullptr);
  const dds_entity_t reader = dds_create_reader(participant.handle(), topic, nullptr, nullptr);
  ASSERT_GT(reader, 0);
  ASSERT_TRUE(waitFor([&] { return publisher.hasSubscribers(); }));

  const std::string frame = "base";
  std::vector<std::string> names{"a", "bc"};
  std::vector<double> positions{1.5};
  dds::StringPointers name_pointers(names);
  sensor_msgs_msg_dds__JointState_ state{};
  state.header.stamp = {1, 2};
  dds::lend(state.header.frame_id, frame);
  name_pointers.lendTo(state.name);
  dds::lend(state.position, positions);
  ASSERT_TRUE(publisher.publish(state));

  struct ddsi_serdata* serdata = nullptr;
  dds_sample_info_t info;
  ASSERT_TRUE(waitFor([&] { return dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE) == 1; }));
  std::vector<uint8_t> wire(ddsi_serdata_size(serdata));
  ddsi_serdata_to_ser(serdata, 0, wire.size(), wire.data());
  ddsi_serdata_unref(serdata);
  std::vector<uint8_t> golden = dds::serializeCdr(type, &state);
  EXPECT_EQ(std::vector<uint8_t>(wire.begin(), wire.begin() + 4),
            (std::vector<uint8_t>{0x00, 0x01, 0x00, 0x00}));
  EXPECT_EQ(std::vector<uint8_t>(wire.begin() + 4, wire.end()),
            std::vector<uint8_t>(golden.begin() + 4, golden.end()));
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
