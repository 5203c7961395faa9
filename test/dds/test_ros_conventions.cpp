// ROS 2's naming, QoS depth, USER_DATA, domain and discovery-configuration rules (pure functions).
#include <gtest/gtest.h>

#include <stdexcept>

#include "serial_robot_driver/dds/ros_conventions.h"
#include "serial_robot_driver/dds/time.h"

namespace dds = serial_robot_driver::dds;

TEST(RosConventions, TopicNamesAreRtPlusTheFullyQualifiedName) {
  EXPECT_EQ(dds::ros2TopicName("/", "joint_states"), "rt/joint_states");
  EXPECT_EQ(dds::ros2TopicName("", "imu/data"), "rt/imu/data");
  EXPECT_EQ(dds::ros2TopicName("/robot1", "joint_states"), "rt/robot1/joint_states");
  EXPECT_EQ(dds::ros2TopicName("robot1/", "imu/data"), "rt/robot1/imu/data");
  // Absolute names ignore the namespace (/tf, /diagnostics are global by convention).
  EXPECT_EQ(dds::ros2TopicName("/robot1", "/tf"), "rt/tf");
  EXPECT_EQ(dds::normalizedNamespace("//a//b/"), "/a/b");
  EXPECT_EQ(dds::normalizedNamespace(""), "/");
}

TEST(RosConventions, TfKeepsAHundredEverythingElseTen) {
  EXPECT_EQ(dds::defaultHistoryDepth("tf"), 100);
  EXPECT_EQ(dds::defaultHistoryDepth("/tf"), 100);
  EXPECT_EQ(dds::defaultHistoryDepth("tf_static"), 10);
  EXPECT_EQ(dds::defaultHistoryDepth("joint_states"), 10);
}

TEST(RosConventions, UserDataStrings) {
  EXPECT_EQ(dds::typeHashUserData("RIHS01_00ff"), "typehash=RIHS01_00ff;");
  EXPECT_EQ(dds::enclaveUserData(), "enclave=/;");
}

TEST(RosConventions, DomainFromConfigurationOrEnvironment) {
  EXPECT_EQ(dds::resolveDomainId(-1, nullptr), 0);
  EXPECT_EQ(dds::resolveDomainId(-1, ""), 0);
  EXPECT_EQ(dds::resolveDomainId(-1, "42"), 42);
  EXPECT_EQ(dds::resolveDomainId(7, "42"), 7);
  EXPECT_EQ(dds::resolveDomainId(232, nullptr), 232);
  EXPECT_THROW(dds::resolveDomainId(233, nullptr), std::invalid_argument);
  EXPECT_THROW(dds::resolveDomainId(-2, nullptr), std::invalid_argument);
  EXPECT_THROW(dds::resolveDomainId(-1, "seven"), std::invalid_argument);
  EXPECT_THROW(dds::resolveDomainId(-1, "300"), std::invalid_argument);
}

TEST(RosConventions, NoPeersMeansCycloneDefaults) { EXPECT_EQ(dds::discoveryConfigXml({}), ""); }

TEST(RosConventions, LoopbackPeersKeepDiscoveryOnLoopback) {
  const std::string xml = dds::discoveryConfigXml({"127.0.0.1", "localhost"});
  EXPECT_NE(xml.find("<NetworkInterface address=\"127.0.0.1\"/>"), std::string::npos);
  EXPECT_NE(xml.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"127.0.0.1\"/><Peer address=\"localhost\"/>"),
            std::string::npos);
  EXPECT_NE(xml.find("<ParticipantIndex>auto</ParticipantIndex>"), std::string::npos);
}

TEST(RosConventions, AnyOtherPeerKeepsEveryInterfaceAndMulticast) {
  const std::string xml = dds::discoveryConfigXml({"127.0.0.1", "192.168.1.20"});
  EXPECT_EQ(xml.find("NetworkInterface"), std::string::npos);
  EXPECT_EQ(xml.find("AllowMulticast"), std::string::npos);
  EXPECT_NE(xml.find("<Peer address=\"192.168.1.20\"/>"), std::string::npos);
  EXPECT_FALSE(dds::isLoopbackAddress("128.0.0.1"));
  EXPECT_TRUE(dds::isLoopbackAddress("127.1.2.3"));
}

TEST(RosConventions, StampsSplitAsRos2Does) {
  const auto stamp = dds::timeFromNanoseconds(1700000000123456789LL);
  EXPECT_EQ(stamp.sec, 1700000000);
  EXPECT_EQ(stamp.nanosec, 123456789u);
  EXPECT_EQ(dds::toNanoseconds(stamp), 1700000000123456789LL);
  const auto before_zero = dds::durationFromNanoseconds(-1);
  EXPECT_EQ(before_zero.sec, -1);
  EXPECT_EQ(before_zero.nanosec, 999999999u);
  EXPECT_EQ(dds::toNanoseconds(before_zero), -1);
}
