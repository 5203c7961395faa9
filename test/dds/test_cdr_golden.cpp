// Golden CDR bytes, written by hand from the ROS 2 message definitions and the CDR (XCDR1) rules:
// a 4-byte encapsulation header 00 01 00 00 (CDR, little-endian), every primitive aligned to its
// size relative to the end of the header (doubles to 8), strings as a uint32 length that counts
// the terminating NUL then the bytes and the NUL, sequences as a uint32 count then the elements
// (aligned only when there is one), fixed arrays as their elements. Both directions: a sample
// serializes to the bytes, the bytes decode to the sample.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cdr_golden_support.h"
#include "serial_robot_driver/dds/c_types.h"

namespace dds = serial_robot_driver::dds;

namespace {

using namespace cdr_golden;

// --- std_msgs/Bool --------------------------------------------------------------------------
const Bytes kBoolTrue = cat({kHeader, {0x01}});

TEST(CdrGolden, BoolBothWays) {
  std_msgs_msg_dds__Bool_ value{true};
  EXPECT_EQ(serialized(value), kBoolTrue);
  Decoded<std_msgs_msg_dds__Bool_> decoded(kBoolTrue);
  ASSERT_TRUE(decoded.ok);
  EXPECT_TRUE(decoded.sample.data);
}

// A null string (a field left unset) goes out as the empty string: length 1, one NUL.
TEST(CdrGolden, UnsetStringIsTheEmptyString) {
  std_msgs_msg_dds__Header_ header{};
  header.stamp = {-1, 999999999};
  const Bytes expected =
      cat({kHeader, {0xff, 0xff, 0xff, 0xff, 0xff, 0xc9, 0x9a, 0x3b}, {0x01, 0, 0, 0, 0x00}});
  EXPECT_EQ(serialized(header), expected);
  Decoded<std_msgs_msg_dds__Header_> decoded(expected);
  ASSERT_TRUE(decoded.ok);
  EXPECT_EQ(decoded.sample.stamp.sec, -1);
  EXPECT_EQ(decoded.sample.stamp.nanosec, 999999999u);
  EXPECT_EQ(dds::text(decoded.sample.frame_id), "");
}

// What Cyclone itself sends for the same Bool: padded to 4, the padding counted in the options.
TEST(CdrGolden, PaddedBoolDecodes) {
  Decoded<std_msgs_msg_dds__Bool_> decoded(Bytes{0x00, 0x01, 0x00, 0x03, 0x01, 0x00, 0x00, 0x00});
  ASSERT_TRUE(decoded.ok);
  EXPECT_TRUE(decoded.sample.data);
  EXPECT_FALSE(Decoded<std_msgs_msg_dds__Bool_>(Bytes{0x00, 0x01, 0x00, 0x03, 0x01}).ok);
}

// --- geometry_msgs/Twist ----------------------------------------------------------------------
const Bytes kTwist = cat({kHeader, kOne, kTwo, kThree, kZero, kZero, kHalf});

TEST(CdrGolden, TwistBothWays) {
  geometry_msgs_msg_dds__Twist_ twist{};
  twist.linear = {1.0, 2.0, 3.0};
  twist.angular.z = 0.5;
  EXPECT_EQ(serialized(twist), kTwist);
  Decoded<geometry_msgs_msg_dds__Twist_> decoded(kTwist);
  ASSERT_TRUE(decoded.ok);
  EXPECT_EQ(decoded.sample.linear.x, 1.0);
  EXPECT_EQ(decoded.sample.linear.y, 2.0);
  EXPECT_EQ(decoded.sample.linear.z, 3.0);
  EXPECT_EQ(decoded.sample.angular.z, 0.5);
}

TEST(CdrGolden, BigEndianTwistDecodes) {
  const Bytes big_endian_one{0x3f, 0xf0, 0, 0, 0, 0, 0, 0};
  const Bytes bytes = cat({{0x00, 0x00, 0x00, 0x00}, big_endian_one, zeros(40)});
  Decoded<geometry_msgs_msg_dds__Twist_> decoded(bytes);
  ASSERT_TRUE(decoded.ok);
  EXPECT_EQ(decoded.sample.linear.x, 1.0);
}

// --- sensor_msgs/JointState -------------------------------------------------------------------
// header {stamp {1, 2}, frame_id "base"}, name ["a", "bc"], position [1.5], velocity [], effort [].
// One row per field, as on the wire.
// clang-format off
const Bytes kJointState = cat({kHeader,
                               {0x01, 0, 0, 0, 0x02, 0, 0, 0},              // 0: sec, nanosec
                               {0x05, 0, 0, 0, 'b', 'a', 's', 'e', 0x00},   // 8: "base"
                               {0, 0, 0},                                   // 17: pad to 4
                               {0x02, 0, 0, 0},                             // 20: two names
                               {0x02, 0, 0, 0, 'a', 0x00, 0, 0},            // 24: "a", pad
                               {0x03, 0, 0, 0, 'b', 'c', 0x00, 0},          // 32: "bc", pad
                               {0x01, 0, 0, 0, 0, 0, 0, 0},                 // 40: one position, pad
                               kOneAndHalf,                                 // 48: 1.5
                               {0, 0, 0, 0, 0, 0, 0, 0}});                  // 56: no vel., effort
// clang-format on

TEST(CdrGolden, JointStateSerializes) {
  const GoldenJointState state;
  EXPECT_EQ(serialized(state.sample()), kJointState);
}

TEST(CdrGolden, JointStateDecodes) {
  Decoded<sensor_msgs_msg_dds__JointState_> decoded(kJointState);
  ASSERT_TRUE(decoded.ok);
  const auto& state = decoded.sample;
  EXPECT_EQ(state.header.stamp.sec, 1);
  EXPECT_EQ(state.header.stamp.nanosec, 2u);
  EXPECT_EQ(dds::text(state.header.frame_id), "base");
  EXPECT_EQ(dds::toStrings(state.name), (std::vector<std::string>{"a", "bc"}));
  EXPECT_EQ(dds::toVector(state.position), std::vector<double>{1.5});
  EXPECT_TRUE(dds::toVector(state.velocity).empty());
  EXPECT_TRUE(dds::toVector(state.effort).empty());
}

TEST(CdrGolden, TruncatedOrForeignBytesAreRefused) {
  for (size_t keep : {0u, 3u, 4u, 20u, 47u, 63u}) {
    const Bytes truncated(kJointState.begin(), kJointState.begin() + keep);
    Decoded<sensor_msgs_msg_dds__JointState_> decoded(truncated);
    EXPECT_FALSE(decoded.ok) << keep << " bytes";
  }
  Bytes huge_name_count = kJointState;
  huge_name_count[4 + 20 + 3] = 0x7f;  // 2 names -> 0x7f000002
  EXPECT_FALSE(Decoded<sensor_msgs_msg_dds__JointState_>(huge_name_count).ok);
  Bytes parameter_list = kBoolTrue;
  parameter_list[1] = 0x03;  // PL_CDR_LE: not what ROS 2 sends
  EXPECT_FALSE(Decoded<std_msgs_msg_dds__Bool_>(parameter_list).ok);
}

/// kJointState with the 4 bytes at payload offset `at` replaced by `value` (little-endian).
Bytes jointStateWith(size_t at, uint32_t value) {
  Bytes bytes = kJointState;
  for (int i = 0; i < 4; ++i) bytes[4 + at + i] = static_cast<uint8_t>(value >> (8 * i));
  return bytes;
}

// Hostile lengths (a peer's bytes): refused before anything is allocated or read past the payload.
// Each would otherwise ask for gigabytes (2^32-1 strings, 2^29 doubles: 2^32 bytes, 0 in 32 bits).
TEST(CdrGolden, OversizeLengthsAreRefusedBeforeAnythingIsAllocated) {
  const struct {
    size_t at;
    uint32_t value;
    const char* what;
  } hostile[] = {
      {8, 0xffffffff, "frame_id of 2^32-1 bytes"},
      {8, 0x40, "frame_id longer than the payload"},
      {8, 0, "frame_id of 0 bytes (no NUL)"},
      {8, 4, "frame_id without its NUL"},
      {20, 0xffffffff, "2^32-1 names"},
      {24, 0xffffffff, "a name of 2^32-1 bytes"},
      {40, 0x20000000, "2^29 positions"},
      {40, 0xffffffff, "2^32-1 positions"},
      {56, 0x1fffffff, "2^29-1 velocities"},
  };
  for (const auto& bad : hostile) {
    Decoded<sensor_msgs_msg_dds__JointState_> decoded(jointStateWith(bad.at, bad.value));
    EXPECT_FALSE(decoded.ok) << bad.what;
  }
  // trajectory_msgs/JointTrajectory: header {0, 0, ""}, no joint names, 2^32-1 points.
  const Bytes trajectory =
      cat({kHeader, zeros(8), {0x01, 0, 0, 0, 0x00, 0, 0, 0}, zeros(4), {0xff, 0xff, 0xff, 0xff}});
  EXPECT_FALSE(Decoded<trajectory_msgs_msg_dds__JointTrajectory_>(trajectory).ok);
}

}  // namespace
