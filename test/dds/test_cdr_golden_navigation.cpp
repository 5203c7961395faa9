// Golden CDR bytes (rules in test_cdr_golden.cpp) of the larger types: Imu, Odometry, TFMessage.
// Offsets in the comments are relative to the end of the encapsulation header.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cdr_golden_support.h"
#include "serial_robot_driver/dds/c_types.h"

using namespace cdr_golden;

namespace {

// --- sensor_msgs/Imu --------------------------------------------------------------------------
// header {stamp {10, 20}, frame_id "imu"}, orientation identity, orientation_covariance[0] -1,
// angular_velocity (0.5, 0, 0), linear_acceleration (0, 0, 8), other covariances 0.
// One row per field, as on the wire.
// clang-format off
const Bytes kImu = cat({kHeader,
                        {0x0a, 0, 0, 0, 0x14, 0, 0, 0},                // 0: sec, nanosec
                        {0x04, 0, 0, 0, 'i', 'm', 'u', 0x00},          // 8: "imu"
                        kIdentityQuaternion,                           // 16: orientation
                        kMinusOne, zeros(8 * 8),                       // 48: covariance
                        kHalf, kZero, kZero,                           // 120: angular_velocity
                        zeros(9 * 8),                                  // 144: covariance
                        kZero, kZero, kEight,                          // 216: linear_acceleration
                        zeros(9 * 8)});                                // 240: covariance
// clang-format on

TEST(CdrGolden, ImuSerializes) {
  const std::string frame = "imu";
  sensor_msgs_msg_dds__Imu_ imu{};
  imu.header.stamp = {10, 20};
  dds::lend(imu.header.frame_id, frame);
  imu.orientation.w = 1.0;
  imu.orientation_covariance[0] = -1.0;
  imu.angular_velocity.x = 0.5;
  imu.linear_acceleration.z = 8.0;
  EXPECT_EQ(serialized(imu), kImu);
}

TEST(CdrGolden, ImuDecodes) {
  Decoded<sensor_msgs_msg_dds__Imu_> decoded(kImu);
  ASSERT_TRUE(decoded.ok);
  const auto& imu = decoded.sample;
  EXPECT_EQ(imu.header.stamp.sec, 10);
  EXPECT_EQ(imu.header.stamp.nanosec, 20u);
  EXPECT_EQ(dds::text(imu.header.frame_id), "imu");
  EXPECT_EQ(imu.orientation.w, 1.0);
  EXPECT_EQ(imu.orientation_covariance[0], -1.0);
  EXPECT_EQ(imu.orientation_covariance[8], 0.0);
  EXPECT_EQ(imu.angular_velocity.x, 0.5);
  EXPECT_EQ(imu.linear_acceleration.z, 8.0);
}

// --- nav_msgs/Odometry ------------------------------------------------------------------------
// header {stamp {3, 4}, frame_id "odom"}, child_frame_id "base_link", pose position (1, 2, 0),
// identity orientation, covariance[0] 0.5, twist linear.x 0.25, angular.z -0.5, covariance 0.
// One row per field, as on the wire.
// clang-format off
const Bytes kOdometry = cat({kHeader,
                             {0x03, 0, 0, 0, 0x04, 0, 0, 0},                        // 0
                             {0x05, 0, 0, 0, 'o', 'd', 'o', 'm', 0x00, 0, 0, 0},    // 8: "odom"
                             {0x0a, 0, 0, 0, 'b', 'a', 's', 'e', '_', 'l', 'i', 'n', 'k', 0x00},
                             {0, 0, 0, 0, 0, 0},                                    // 34: pad
                             kOne, kTwo, kZero,                                     // 40
                             kIdentityQuaternion,                                   // 64
                             kHalf, zeros(35 * 8),                                  // 96
                             kQuarter, kZero, kZero,                                // 384
                             kZero, kZero, kMinusHalf,                              // 408
                             zeros(36 * 8)});                                       // 432
// clang-format on

TEST(CdrGolden, OdometrySerializes) {
  const std::string frame = "odom";
  const std::string child = "base_link";
  nav_msgs_msg_dds__Odometry_ odometry{};
  odometry.header.stamp = {3, 4};
  dds::lend(odometry.header.frame_id, frame);
  dds::lend(odometry.child_frame_id, child);
  odometry.pose.pose.position = {1.0, 2.0, 0.0};
  odometry.pose.pose.orientation.w = 1.0;
  odometry.pose.covariance[0] = 0.5;
  odometry.twist.twist.linear.x = 0.25;
  odometry.twist.twist.angular.z = -0.5;
  EXPECT_EQ(serialized(odometry), kOdometry);
}

TEST(CdrGolden, OdometryDecodes) {
  Decoded<nav_msgs_msg_dds__Odometry_> decoded(kOdometry);
  ASSERT_TRUE(decoded.ok);
  const auto& odometry = decoded.sample;
  EXPECT_EQ(odometry.header.stamp.sec, 3);
  EXPECT_EQ(dds::text(odometry.header.frame_id), "odom");
  EXPECT_EQ(dds::text(odometry.child_frame_id), "base_link");
  EXPECT_EQ(odometry.pose.pose.position.y, 2.0);
  EXPECT_EQ(odometry.pose.pose.orientation.w, 1.0);
  EXPECT_EQ(odometry.pose.covariance[0], 0.5);
  EXPECT_EQ(odometry.twist.twist.linear.x, 0.25);
  EXPECT_EQ(odometry.twist.twist.angular.z, -0.5);
}

// --- tf2_msgs/TFMessage -----------------------------------------------------------------------
// one transform: header {stamp {5, 6}, frame_id "odom"}, child "base_link", translation (1, 0, 0),
// identity rotation.
// One row per field, as on the wire.
// clang-format off
const Bytes kTfMessage = cat({kHeader,
                              {0x01, 0, 0, 0},                                       // 0: count
                              {0x05, 0, 0, 0, 0x06, 0, 0, 0},                        // 4: stamp
                              {0x05, 0, 0, 0, 'o', 'd', 'o', 'm', 0x00, 0, 0, 0},    // 12
                              {0x0a, 0, 0, 0, 'b', 'a', 's', 'e', '_', 'l', 'i', 'n', 'k', 0x00},
                              {0, 0},                                                // 38: pad
                              kOne, kZero, kZero,                                    // 40
                              kIdentityQuaternion});                                 // 64
// clang-format on

TEST(CdrGolden, TfMessageSerializes) {
  const std::string frame = "odom";
  const std::string child = "base_link";
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms(1);
  transforms[0].header.stamp = {5, 6};
  dds::lend(transforms[0].header.frame_id, frame);
  dds::lend(transforms[0].child_frame_id, child);
  transforms[0].transform.translation.x = 1.0;
  transforms[0].transform.rotation.w = 1.0;
  tf2_msgs_msg_dds__TFMessage_ message{};
  dds::lend(message.transforms, transforms);
  EXPECT_EQ(serialized(message), kTfMessage);
}

TEST(CdrGolden, TfMessageDecodes) {
  Decoded<tf2_msgs_msg_dds__TFMessage_> decoded(kTfMessage);
  ASSERT_TRUE(decoded.ok);
  const auto transforms = dds::toVector(decoded.sample.transforms);
  ASSERT_EQ(transforms.size(), 1u);
  EXPECT_EQ(transforms[0].header.stamp.nanosec, 6u);
  EXPECT_EQ(dds::text(transforms[0].header.frame_id), "odom");
  EXPECT_EQ(dds::text(transforms[0].child_frame_id), "base_link");
  EXPECT_EQ(transforms[0].transform.translation.x, 1.0);
  EXPECT_EQ(transforms[0].transform.rotation.w, 1.0);
}

}  // namespace
