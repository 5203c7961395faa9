// driver_node's servo controller board (body_node.test): telemetry bytes written to the pty come
// out exactly as joint_states, imu/data, foot_pressure and telemetry.
#include <gtest/gtest.h>

#include "support/body_node_fixture.h"

namespace {

using namespace body_node_test;  // NOLINT: the shared fixture

TEST_F(BodyNode, GoldenFrameGivesExactJointStateImuAndTelemetry) {
  const ros::Time before = ros::Time::now();
  board().write(kGolden);
  board().write(kSentinel);
  const auto joints = board().joints.waitFor([](const JointState& m) { return isSentinel(m); });
  const auto imu = board().imu.waitFor([](const Imu& m) { return isSentinel(m); });
  const auto telemetry =
      board().telemetry.waitFor([](const Telemetry& m) { return isSentinel(m); });
  const ros::Time after = ros::Time::now();
  ASSERT_TRUE(joints && imu && telemetry);
  ASSERT_EQ(joints->size(), 1u);
  ASSERT_EQ(imu->size(), 1u);
  ASSERT_EQ(telemetry->size(), 1u);

  // Joints: hip = 2048 - 2048 = 0; knee (direction -1) = -(1024 - 2048) ticks = pi/2;
  // no velocity: its scale is unknown (velocity_scale 0), so it is left empty, not guessed.
  const JointState& js = joints->front();
  EXPECT_EQ(js.name, (std::vector<std::string>{"hip", "knee"}));
  ASSERT_EQ(js.position.size(), 2u);
  EXPECT_TRUE(js.velocity.empty());
  EXPECT_NEAR(js.position[0], 0.0, 1e-12);
  EXPECT_NEAR(js.position[1], M_PI / 2, 1e-12);
  // Stamped with the arrival of the frame's last byte: after we wrote it, before we got it.
  EXPECT_GE(js.header.stamp.toSec(), before.toSec() - 1e-3);
  EXPECT_LE(js.header.stamp, after);

  // IMU: accel_scale 0.5, gyro_scale 0.25, default angle_scale: yaw -16384 LSB = -90 deg.
  const Imu& m = imu->front();
  EXPECT_EQ(m.header.frame_id, "imu_test");
  EXPECT_EQ(m.header.stamp, js.header.stamp);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.x, 0.5);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.y, -0.5);
  EXPECT_DOUBLE_EQ(m.linear_acceleration.z, 8192.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.x, 0.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.y, 0.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity.z, 25.0);
  EXPECT_NEAR(m.orientation.x, 0.0, 1e-9);
  EXPECT_NEAR(m.orientation.y, 0.0, 1e-9);
  EXPECT_NEAR(std::abs(m.orientation.z), std::sqrt(0.5), 1e-5);
  EXPECT_NEAR(std::abs(m.orientation.w), std::sqrt(0.5), 1e-5);
  EXPECT_LT(m.orientation.z * m.orientation.w, 0.0);  // negative yaw
  EXPECT_GT(m.orientation_covariance[0], 0.0);
  EXPECT_EQ(m.orientation_covariance[1], 0.0);

  // Telemetry: the raw frame.
  const Telemetry& t = telemetry->front();
  EXPECT_EQ(t.header.stamp, js.header.stamp);
  EXPECT_EQ(t.servo_ids, (std::vector<uint8_t>{2, 3}));
  EXPECT_EQ(t.positions, (std::vector<uint16_t>{2048, 1024}));
  EXPECT_EQ(t.speeds, (std::vector<int16_t>{10, -5}));
  const boost::array<int16_t, 9> raw_imu = {1, -1, 16384, 0, 0, 100, 0, 0, -16384};
  EXPECT_EQ(t.imu, raw_imu);
  EXPECT_FALSE(t.has_foot);
  EXPECT_TRUE(t.foot.empty());
}

TEST_F(BodyNode, OnlyIntactFramesArePublished) {
  const Bytes junk = {0x00, 0xFF, 0x12, 0x00, 0x34, 0x1F, 0x2F, 0x12};
  const Bytes bad_sum = withByte(kGolden, 29, 0x94);
  const Bytes bad_tail = withByte(kGolden, 31, 0x2E);
  const Bytes truncated(kGolden.begin(), kGolden.begin() + 10);
  const Bytes bad_len = withByte(kGolden, 2, 0x24);  // LEN of 3 servos: impossible for N = 2
  const std::vector<Bytes> stream = {junk,    kGolden, bad_sum, kGolden, bad_tail, truncated,
                                     kGolden, bad_len, junk,    kGolden, kSentinel};
  for (const Bytes& chunk : stream) board().write(chunk);

  const auto joints = board().joints.waitFor([](const JointState& m) { return isSentinel(m); });
  const auto telemetry =
      board().telemetry.waitFor([](const Telemetry& m) { return isSentinel(m); });
  ASSERT_TRUE(joints && telemetry);
  EXPECT_EQ(joints->size(), 4u);
  EXPECT_EQ(telemetry->size(), 4u);
  for (const JointState& js : *joints) {
    ASSERT_EQ(js.position.size(), 2u);
    EXPECT_NEAR(js.position[0], 0.0, 1e-12);
    EXPECT_NEAR(js.position[1], M_PI / 2, 1e-12);
  }
}

TEST_F(BodyNode, ByteByByteDeliveryPublishesEveryFrame) {
  for (const Bytes* frame : {&kGolden, &kFoot, &kGolden, &kSentinel}) {
    for (uint8_t byte : *frame) {
      board().write(Bytes{byte});
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  }
  const auto joints = board().joints.waitFor([](const JointState& m) { return isSentinel(m); });
  ASSERT_TRUE(joints);
  EXPECT_EQ(joints->size(), 3u);
}

TEST_F(BodyNode, FootPressureOnlyForFramesWithTheFootBlock) {
  for (const Bytes* frame : {&kGolden, &kFoot, &kGolden, &kFoot, &kFootSentinel}) {
    board().write(*frame);
  }
  const auto foot = board().foot.waitFor([](const FootPressure& m) { return isFootSentinel(m); });
  const auto telemetry =
      board().telemetry.waitFor([](const Telemetry& m) { return isFootSentinel(m); });
  ASSERT_TRUE(foot && telemetry);
  ASSERT_EQ(foot->size(), 2u);
  const boost::array<uint16_t, 8> expected = {0x0201, 0x0403, 0x0605, 0x0807,
                                              0x0A09, 0x0C0B, 0x0E0D, 0x100F};
  EXPECT_EQ((*foot)[0].pressure, expected);
  EXPECT_EQ((*foot)[1].pressure, expected);

  ASSERT_EQ(telemetry->size(), 4u);
  std::vector<bool> has_foot;
  for (const Telemetry& t : *telemetry) has_foot.push_back(t.has_foot != 0);
  EXPECT_EQ(has_foot, (std::vector<bool>{false, true, false, true}));
  EXPECT_TRUE((*telemetry)[0].foot.empty());
  EXPECT_EQ((*telemetry)[1].foot, (std::vector<uint16_t>{0x0201, 0x0403, 0x0605, 0x0807, 0x0A09,
                                                         0x0C0B, 0x0E0D, 0x100F}));
  // Each foot_pressure message belongs to its frame: the same stamp as that frame's telemetry.
  EXPECT_EQ((*foot)[0].header.stamp, (*telemetry)[1].header.stamp);
  EXPECT_EQ((*foot)[1].header.stamp, (*telemetry)[3].header.stamp);
}

}  // namespace
