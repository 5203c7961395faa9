// REP-2011 type hashes against the values ROS 2 itself publishes, and the hashing on hand-written
// JSON. The expected hashes are copied from what ROS 2 Jazzy prints or pins, never computed here:
// `ros2 topic info -v` output quoted in public issues/docs (JointState, JointTrajectory,
// TFMessage, BatteryState: "Topic type hash: RIHS01_..."), rmw_dds_common's discovery type
// (ParticipantEntitiesInfo, as Cyclone-based rmw reimplementations hard-code it), and the
// type-hash tables of ROS 2 client libraries that check them against Jazzy (the rest).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "serial_robot_driver/dds/messages.h"
#include "serial_robot_driver/dds/type_description.h"

namespace dds = serial_robot_driver::dds;

namespace {

struct PublishedHash {
  const char* type_name;
  const char* hash;
};

const PublishedHash kPublishedHashes[] = {
    {"builtin_interfaces/msg/Time",
     "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197"},
    {"builtin_interfaces/msg/Duration",
     "RIHS01_e8d009f659816f758b75334ee1a9ca5b5c0b859843261f14c7f937349599d93b"},
    {"std_msgs/msg/Header",
     "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"},
    {"std_msgs/msg/Bool",
     "RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9"},
    {"geometry_msgs/msg/Vector3",
     "RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d"},
    {"geometry_msgs/msg/Point",
     "RIHS01_6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881"},
    {"geometry_msgs/msg/Quaternion",
     "RIHS01_8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684"},
    {"geometry_msgs/msg/Twist",
     "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"},
    {"geometry_msgs/msg/TwistStamped",
     "RIHS01_5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64"},
    {"geometry_msgs/msg/TransformStamped",
     "RIHS01_0a241f87d04668d94099cbb5ba11691d5ad32c2f29682e4eb5653424bd275206"},
    {"sensor_msgs/msg/JointState",
     "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e"},
    {"sensor_msgs/msg/Imu",
     "RIHS01_7d9a00ff131080897a5ec7e26e315954b8eae3353c3f995c55faf71574000b5b"},
    {"sensor_msgs/msg/BatteryState",
     "RIHS01_4bee5dfce981c98faa6828b868307a0a73f992ed0789f374ee96c8f840e69741"},
    {"nav_msgs/msg/Odometry",
     "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"},
    {"tf2_msgs/msg/TFMessage",
     "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"},
    {"diagnostic_msgs/msg/KeyValue",
     "RIHS01_d68081eaa540288c5440753baecef0c4e16e81a5f78ad68902ded5100413bb42"},
    {"diagnostic_msgs/msg/DiagnosticStatus",
     "RIHS01_b0e3e692ea2d54a8af2f4ef1930e81556a2db55216b771f8a7d2724ed47bf0e4"},
    {"diagnostic_msgs/msg/DiagnosticArray",
     "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e"},
    {"trajectory_msgs/msg/JointTrajectory",
     "RIHS01_179b33eba59d676f6d967ac71fe35e7ca2f64b2f3928f4a018cec115e213796e"},
    {"rmw_dds_common/msg/ParticipantEntitiesInfo",
     "RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e"},
};

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
