// driver_node with the AP1 wheeled base (base_node.test): the Reset after connecting, the
// heartbeat, and cmd_vel turned into speed frames (straight, turning, slow, clamped, timed out,
// NaN). The machine may be busy: the tests count frames and use generous deadlines, never tight
// timing.
#include <gtest/gtest.h>

#include "support/base_node_fixture.h"

namespace {

using namespace base_node_test;  // NOLINT: the shared fixture

// The hand-written XOR helper reproduces the golden vectors of docs/protocols.md, so the expected
// frames built with it below can be trusted.
TEST(BaseGoldenFrames, HelperMatchesProtocolVectors) {
  EXPECT_EQ(resetFrame(0x02), golden::base::kResetSeq2);
  EXPECT_EQ(batteryRequestFrame(0x01), golden::base::kBatteryRequestSeq1);
  EXPECT_EQ(clearEncodersFrame(0x03), golden::base::kClearEncodersSeq3);
  EXPECT_EQ(withXor({0x55, 0xAA, 0x09, 0x00, 0x01, 0xFF, 0xFA, 0xFF, 0xFA, 0x00, 0x00, 0x00, 0x00}),
            golden::base::kBothMinus6Seq0);
}

// 1. After connecting, the node sends a Reset, then a speed frame reported with reset_before.
TEST_F(BaseNodeTest, ResetIsTheFirstFrameAfterConnect) {
  const std::vector<SeenFrame> frames = base_->frames();
  ASSERT_GE(frames.size(), 2u);
  EXPECT_EQ(frames[0].bytes, resetFrame(frames[0].seq));
  ASSERT_TRUE(frames[1].isSpeed()) << "MSGID " << int(frames[1].msg_id);
  EXPECT_EQ(frames[1].seq, static_cast<uint8_t>(frames[0].seq + 1));
  EXPECT_EQ(frames[1].bytes.size(), 14u);

  ASSERT_TRUE(g_ros->waitWheelCommand(frames[1].seq, base_->pluggedAt(), 5.0));
  const auto command = g_ros->wheelCommand(frames[1].seq, base_->pluggedAt());
  EXPECT_TRUE(command->reset_before);
  EXPECT_EQ(command->left_ticks, frames[1].left());
  EXPECT_EQ(command->right_ticks, frames[1].right());

  // A later speed frame with no Reset just before it is reported without reset_before.
  ASSERT_TRUE(base_->waitForCount(10, 5.0));
  const std::vector<SeenFrame> later = base_->frames();
  const auto plain = findFrom(later, 3, [&](const SeenFrame& f) { return f.isSpeed(); });
  ASSERT_TRUE(plain.has_value());
  ASSERT_FALSE(later[*plain - 1].isReset());
  ASSERT_TRUE(g_ros->waitWheelCommand(later[*plain].seq, base_->pluggedAt(), 5.0));
  EXPECT_FALSE(g_ros->wheelCommand(later[*plain].seq, base_->pluggedAt())->reset_before);
}

// 2. With no cmd_vel the node keeps sending zero-speed frames (the base's heartbeat) at the loop
// rate; SEQ goes up by one per frame and wraps 255 -> 0.
TEST_F(BaseNodeTest, HeartbeatFlowsWithoutCmdVelAndSeqWraps) {
  const std::size_t from = base_->count();
  const Clock::time_point start = Clock::now();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const std::vector<SeenFrame> window = base_->frames();
  std::size_t in_window = 0;
  for (std::size_t i = from; i < window.size(); ++i) {
    if (!window[i].isSpeed()) continue;
    if (window[i].arrival - start > std::chrono::seconds(2)) break;
    EXPECT_TRUE(window[i].isZeroSpeed()) << "frame " << i;
    EXPECT_EQ(window[i].bytes, zeroSpeedFrame(window[i].seq)) << "frame " << i;
    ++in_window;
  }
  // 50 Hz for 2 s; a wide band, the machine may be busy.
  EXPECT_GE(in_window, 60u);
  EXPECT_LE(in_window, 120u);

  // SEQ wraps after 256 frames (about 5 s at 50 Hz plus the battery requests).
  const bool wrapped = base_->waitUntil(
      [](const std::vector<SeenFrame>& frames) {
        for (std::size_t i = 1; i < frames.size(); ++i) {
          if (frames[i - 1].seq == 255 && frames[i].seq == 0) return true;
        }
        return false;
      },
      15.0);
  EXPECT_TRUE(wrapped) << "no 255 -> 0 SEQ wrap seen";
  const std::vector<SeenFrame> all = base_->frames();
  for (std::size_t i = 1; i < all.size(); ++i) {
    ASSERT_EQ(all[i].seq, static_cast<uint8_t>(all[i - 1].seq + 1)) << "frame " << i;
  }
}

// 3a. Straight ahead at 0.2 m/s: both wheels forward, 8.149 ticks per period on average.
TEST_F(BaseNodeTest, StraightDrivesBothWheelsForward) {
  const std::vector<SeenFrame> speed = driveAndCollect(0.2, 0.0, 60);
  ASSERT_EQ(speed.size(), 60u);
  for (const auto& f : speed) {
    EXPECT_EQ(f.left(), f.right());
    EXPECT_TRUE(f.left() == 8 || f.left() == 9) << f.left();
  }
  EXPECT_NEAR(meanLeft(speed), 0.2 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanRight(speed), 0.2 * kTicksAt1Mps, 0.05);
}

// 3b. Turning in place at 0.5 rad/s: left backward, right forward, 0.1 m/s = 4.074 ticks each.
TEST_F(BaseNodeTest, TurnInPlaceSpinsWheelsOpposite) {
  const std::vector<SeenFrame> speed = driveAndCollect(0.0, 0.5, 60);
  ASSERT_EQ(speed.size(), 60u);
  for (const auto& f : speed) {
    EXPECT_LT(f.left(), 0);
    EXPECT_GT(f.right(), 0);
    EXPECT_LE(std::abs(f.left() + f.right()), 2) << f.left() << " " << f.right();
  }
  EXPECT_NEAR(meanLeft(speed), -0.1 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanRight(speed), 0.1 * kTicksAt1Mps, 0.05);
}

// 4. 0.02 m/s is 0.815 ticks per period: the vendor's truncation would send 0 forever; carrying
// the remainder moves the robot at the right speed on average.
TEST_F(BaseNodeTest, LowSpeedMovesOnAverage) {
  const std::vector<SeenFrame> speed = driveAndCollect(0.02, 0.0, 120);
  ASSERT_EQ(speed.size(), 120u);
  int zeros = 0;
  for (const auto& f : speed) {
    EXPECT_TRUE(f.left() == 0 || f.left() == 1) << f.left();
    EXPECT_EQ(f.left(), f.right());
    zeros += f.left() == 0 ? 1 : 0;
  }
  EXPECT_GT(zeros, 0);
  EXPECT_NEAR(meanLeft(speed), 0.02 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanRight(speed), 0.02 * kTicksAt1Mps, 0.05);
}

// 5. 3 m/s with 1 rad/s asks for 2.8 / 3.2 m/s: both wheels are scaled by 1/3.2, so the right
// wheel runs at max_wheel_speed (1 m/s = 40.74 ticks) and the left at 0.875 m/s (35.65 ticks).
TEST_F(BaseNodeTest, FastCommandIsClampedKeepingTheTurnRadius) {
  const std::vector<SeenFrame> speed = driveAndCollect(3.0, 1.0, 60);
  ASSERT_EQ(speed.size(), 60u);
  for (const auto& f : speed) {
    EXPECT_TRUE(f.right() == 40 || f.right() == 41) << f.right();
    EXPECT_TRUE(f.left() == 35 || f.left() == 36) << f.left();
  }
  EXPECT_NEAR(meanRight(speed), kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanLeft(speed), 0.875 * kTicksAt1Mps, 0.05);
  EXPECT_NEAR(meanLeft(speed) / meanRight(speed), 2.8 / 3.2, 0.005);
}

// 6. When cmd_vel stops for longer than cmd_vel_timeout (0.5 s), the wheels are stopped.
TEST_F(BaseNodeTest, CmdVelTimeoutStopsTheWheels) {
  const std::vector<SeenFrame> moving = driveAndCollect(0.2, 0.0, 10);
  ASSERT_EQ(moving.size(), 10u);
  streamer_->stop(false);  // silence, not a zero Twist
  const std::size_t from = base_->count();
  std::size_t first_zero = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto zero = findFrom(frames, from, isZeroSpeedFrame);
        if (!zero) return false;
        first_zero = *zero;
        return speedCount(frames, first_zero) >= 25;
      },
      5.0));
  const std::vector<SeenFrame> after = speedFramesFrom(base_->frames(), first_zero);
  for (const auto& f : after) EXPECT_TRUE(f.isZeroSpeed()) << f.left() << " " << f.right();
}

// 7. A NaN cmd_vel is rejected as "stop", counted in the diagnostics, and the node keeps working.
TEST_F(BaseNodeTest, NanCmdVelStopsTheWheels) {
  ASSERT_EQ(driveAndCollect(0.2, 0.0, 10).size(), 10u);
  const std::string kRejected = "rejected cmd_vel (NaN/Inf)";
  ASSERT_TRUE(waitFor([&] { return !g_ros->baseDiagnostics().value(kRejected).empty(); }, 5.0));
  const uint64_t rejected_before = g_ros->baseDiagnostics().number(kRejected);

  const std::size_t from = base_->count();
  streamer().set(std::numeric_limits<double>::quiet_NaN(), 0.0);  // keeps streaming NaN
  std::size_t first_zero = 0;
  ASSERT_TRUE(base_->waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        const auto zero = findFrom(frames, from, isZeroSpeedFrame);
        if (!zero) return false;
        first_zero = *zero;
        return speedCount(frames, first_zero) >= 40;
      },
      5.0));
  for (const auto& f : speedFramesFrom(base_->frames(), first_zero)) {
    EXPECT_TRUE(f.isZeroSpeed()) << f.left() << " " << f.right();
  }
  EXPECT_TRUE(
      waitFor([&] { return g_ros->baseDiagnostics().number(kRejected) > rejected_before; }, 5.0))
      << "the NaN cmd_vel was not counted as rejected";

  // Still alive and driving.
  EXPECT_EQ(driveAndCollect(0.2, 0.0, 5).size(), 5u);
}

}  // namespace
