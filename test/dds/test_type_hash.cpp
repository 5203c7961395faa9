// REP-2011 type hashes against the values ROS 2 itself publishes (published_type_hashes.h), and the
// hashing on hand-written JSON. The expected hashes are copied from what ROS 2 Jazzy prints or
// pins, never computed here: `ros2 topic info -v` output quoted in public issues/docs (JointState,
// JointTrajectory, TFMessage, BatteryState: "Topic type hash: RIHS01_..."), rmw_dds_common's
// discovery type (ParticipantEntitiesInfo, as Cyclone-based rmw reimplementations hard-code it),
// and the type-hash tables of ROS 2 client libraries that check them against Jazzy (the rest).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "published_type_hashes.h"
#include "serial_robot_driver/dds/messages.h"
#include "serial_robot_driver/dds/type_description.h"

namespace dds = serial_robot_driver::dds;

namespace {

using dds_test::kPublishedHashes;
using dds_test::PublishedHash;

class PublishedTypeHash : public ::testing::TestWithParam<PublishedHash> {};

TEST_P(PublishedTypeHash, EqualsWhatRos2Publishes) {
  EXPECT_EQ(dds::typeHash(GetParam().type_name), GetParam().hash) << GetParam().type_name;
}

INSTANTIATE_TEST_SUITE_P(Jazzy, PublishedTypeHash, ::testing::ValuesIn(kPublishedHashes));

TEST(TypeHash, EveryTypeOfTheTableHasAWellFormedHash) {
  ASSERT_GE(dds::typeDescriptions().size(), 27u);
  for (const auto& type : dds::typeDescriptions()) {
    const std::string hash = dds::typeHash(type.type_name);
    EXPECT_EQ(hash.size(), 7u + 64u) << type.type_name;
    EXPECT_EQ(hash.rfind("RIHS01_", 0), 0u) << type.type_name;
  }
}

// The JSON form, written by hand from rosidl_generator_type_description's rules.
TEST(TypeHash, BoolJsonIsTheExactHashedForm) {
  EXPECT_EQ(dds::hashableTypeDescriptionJson("std_msgs/msg/Bool"),
            "{\"type_description\": {\"type_name\": \"std_msgs/msg/Bool\", \"fields\": [{\"name\": "
            "\"data\", \"type\": {\"type_id\": 15, \"capacity\": 0, \"string_capacity\": 0, "
            "\"nested_type_name\": \"\"}}]}, \"referenced_type_descriptions\": []}");
}

TEST(TypeHash, ReferencedTypesAreListedOnceSortedByName) {
  const std::string json = dds::hashableTypeDescriptionJson("nav_msgs/msg/Odometry");
  const char* referenced_in_order[] = {"builtin_interfaces/msg/Time\", \"fields",
                                       "geometry_msgs/msg/Point\", \"fields",
                                       "geometry_msgs/msg/Pose\", \"fields",
                                       "geometry_msgs/msg/PoseWithCovariance\", \"fields",
                                       "geometry_msgs/msg/Quaternion\", \"fields",
                                       "geometry_msgs/msg/Twist\", \"fields",
                                       "geometry_msgs/msg/TwistWithCovariance\", \"fields",
                                       "geometry_msgs/msg/Vector3\", \"fields",
                                       "std_msgs/msg/Header\", \"fields"};
  size_t position = json.find("referenced_type_descriptions");
  for (const char* name : referenced_in_order) {
    const size_t found = json.find(name, position);
    ASSERT_NE(found, std::string::npos) << name;
    EXPECT_EQ(json.find(name, found + 1), std::string::npos) << name << " listed twice";
    position = found;
  }
}

TEST(TypeHash, BoundedStringsAndFixedArraysCarryTheirCapacities) {
  const std::string json = dds::hashableTypeDescriptionJson("rmw_dds_common/msg/NodeEntitiesInfo");
  EXPECT_NE(json.find("{\"name\": \"node_name\", \"type\": {\"type_id\": 21, \"capacity\": 0, "
                      "\"string_capacity\": 256, \"nested_type_name\": \"\"}}"),
            std::string::npos);
  EXPECT_NE(json.find("{\"name\": \"data\", \"type\": {\"type_id\": 51, \"capacity\": 16, "
                      "\"string_capacity\": 0, \"nested_type_name\": \"\"}}"),
            std::string::npos);
}

TEST(TypeHash, Rihs01IsTheSha256OfTheText) {
  // SHA-256("") and SHA-256("abc"), from FIPS 180-2.
  EXPECT_EQ(dds::rihs01(""),
            "RIHS01_e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(dds::rihs01("abc"),
            "RIHS01_ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(TypeHash, UnknownTypeIsRefused) {
  EXPECT_THROW(dds::typeHash("std_msgs/msg/NoSuchType"), std::invalid_argument);
  EXPECT_EQ(dds::findTypeDescription("std_msgs/msg/NoSuchType"), nullptr);
}

template <typename T>
void expectDdsNameAndDescription(const char* dds_type_name) {
  using Traits = dds::Message<T>;
  EXPECT_STREQ(Traits::descriptor().m_typename, dds_type_name);
  EXPECT_NE(dds::findTypeDescription(Traits::kRosName), nullptr) << Traits::kRosName;
}

// The idlc types carry ROS 2's DDS type names, and each has its type description.
TEST(Messages, GeneratedTypesHaveRos2DdsNames) {
  expectDdsNameAndDescription<std_msgs_msg_dds__Bool_>("std_msgs::msg::dds_::Bool_");
  expectDdsNameAndDescription<geometry_msgs_msg_dds__Twist_>("geometry_msgs::msg::dds_::Twist_");
  expectDdsNameAndDescription<sensor_msgs_msg_dds__JointState_>(
      "sensor_msgs::msg::dds_::JointState_");
  expectDdsNameAndDescription<sensor_msgs_msg_dds__Imu_>("sensor_msgs::msg::dds_::Imu_");
  expectDdsNameAndDescription<nav_msgs_msg_dds__Odometry_>("nav_msgs::msg::dds_::Odometry_");
  expectDdsNameAndDescription<tf2_msgs_msg_dds__TFMessage_>("tf2_msgs::msg::dds_::TFMessage_");
  expectDdsNameAndDescription<rmw_dds_common_msg_dds__ParticipantEntitiesInfo_>(
      "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
}

}  // namespace
