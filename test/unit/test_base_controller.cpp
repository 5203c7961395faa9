// BaseController: the Reset/heartbeat cycle, cmd_vel handling and battery polling, driven with
// explicit time points and a fake port that records every frame.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "serial_robot_driver/device/base_controller.h"

namespace serial_robot_driver::device {
namespace {

using Bytes = std::vector<uint8_t>;
using std::chrono::milliseconds;

class BaseControllerTest : public ::testing::Test {
 protected:
  BaseControllerTest()
      : controller_(config(), [this](const Bytes& frame) { return write(frame); }, events()) {}

  BaseEvents events() {
    BaseEvents events;
    events.on_wheel_frame = [this](const WheelFrameSent& sent) { sent_.push_back(sent); };
    return events;
  }

  static BaseConfig config() {
    BaseConfig c;
    c.battery_poll_rate = 0;  // tests that want polling enable it on their own controller
    return c;
  }

  bool write(const Bytes& frame) {
    if (!port_up_) return false;
    frames_.push_back(frame);
    return true;
  }

  BaseController controller_;
  std::vector<Bytes> frames_;
  std::vector<WheelFrameSent> sent_;
  bool port_up_ = true;
  const Clock::time_point t0_ = Clock::now();
};

TEST_F(BaseControllerTest, FirstSpeedFrameIsPrecededByReset) {
  controller_.sendSpeed(t0_, false);
  ASSERT_EQ(frames_.size(), 2u);
  // Reset, SEQ 00: 55^AA^02^00^05^00 = F8
  EXPECT_EQ(frames_[0], (Bytes{0x55, 0xAA, 0x02, 0x00, 0x05, 0x00, 0xF8}));
  // zero speed, SEQ 01: XOR = 55^AA^09^01^01 = F6
  EXPECT_EQ(frames_[1], (Bytes{0x55, 0xAA, 0x09, 0x01, 0x01, 0, 0, 0, 0, 0, 0, 0, 0, 0xF6}));
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_TRUE(sent_[0].reset_before);
  EXPECT_EQ(sent_[0].seq, 1);
}

TEST_F(BaseControllerTest, HeartbeatFramesCountSequenceWithoutResets) {
  for (int i = 0; i < 300; ++i) controller_.tick(t0_ + milliseconds(20 * i));
  ASSERT_EQ(frames_.size(), 301u);  // one Reset, then one speed frame per tick
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    EXPECT_EQ(frames_[i][3], static_cast<uint8_t>(i)) << "SEQ wraps 255 -> 0, one per frame";
  }
  EXPECT_EQ(controller_.stats().resets_sent, 1u);
}

TEST_F(BaseControllerTest, StraightCommandGivesEqualPositiveTicks) {
  controller_.setCommand(0.1, 0.0);
  controller_.sendSpeed(Clock::now(), true);
  ASSERT_EQ(frames_.size(), 2u);
  // 0.1 m/s = 4.07 ticks per period -> 4 on the first frame; SEQ 01: XOR = F7 ^ 01 = F6
  EXPECT_EQ(frames_[1], (Bytes{0x55, 0xAA, 0x09, 0x01, 0x01, 0x00, 0x04, 0x00, 0x04, 0, 0, 0, 0, 0xF6}));
}

TEST_F(BaseControllerTest, TurnInPlaceGivesOppositeTicks) {
  controller_.setCommand(0.0, 1.0);  // wheels at -/+ 0.2 m/s
  controller_.sendSpeed(Clock::now(), true);
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_LT(sent_[0].ticks.left, 0);
  EXPECT_EQ(sent_[0].ticks.left, -sent_[0].ticks.right);
  EXPECT_EQ(sent_[0].ticks.right, 8);
}

TEST_F(BaseControllerTest, HugeCommandKeepsItsDirectionAtFullSpeed) {
  controller_.setCommand(1e308, 1e308);  // the wheel sum would overflow to inf
  controller_.sendSpeed(Clock::now(), true);
  ASSERT_EQ(sent_.size(), 1u);
  EXPECT_NEAR(sent_[0].speeds.y(), 1.0, 1e-9) << "the faster wheel at max_wheel_speed";
  EXPECT_GT(sent_[0].speeds.x(), 0.0);
  EXPECT_LT(sent_[0].speeds.x(), 1.0);
  EXPECT_EQ(sent_[0].ticks.right, 41);  // 40.74 ticks per period, rounded on the first frame
}

TEST_F(BaseControllerTest, CommandTimesOutToZero) {
  controller_.setCommand(0.5, 0.0);
  const Clock::time_point now = Clock::now();
  controller_.sendSpeed(now, true);
  ASSERT_GT(sent_.back().ticks.left, 0);
  controller_.sendSpeed(now + milliseconds(600), false);  // cmd_vel_timeout is 0.5 s
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().cmd_vel_timeouts, 1u);
}

TEST_F(BaseControllerTest, NonFiniteCommandIsRejectedAsZero) {
  controller_.setCommand(0.5, 0.0);
  EXPECT_FALSE(controller_.setCommand(std::nan(""), 0.0));
  EXPECT_FALSE(controller_.setCommand(0.1, INFINITY));
  controller_.sendSpeed(Clock::now(), true);
  EXPECT_EQ(sent_.back().ticks, (kinematics::WheelTicks{0, 0}));
  EXPECT_EQ(controller_.stats().rejected_commands, 2u);
}

TEST_F(BaseControllerTest, TimeoutErrorFrameMakesNextFrameReset) {
  controller_.sendSpeed(t0_, false);
  controller_.sendSpeed(t0_ + milliseconds(20), false);
  frames_.clear();
  // FF error status from the base, SEQ 07: 55^AA^02^07^FF^00 = 05
  const Bytes error = {0x55, 0xAA, 0x02, 0x07, 0xFF, 0x00, 0x05};
  controller_.onFrame(protocol::FrameFamily::kBase, error.data(), error.size(), Clock::now());
  controller_.sendSpeed(t0_ + milliseconds(40), false);
  ASSERT_EQ(frames_.size(), 2u);
  EXPECT_EQ(frames_[0][4], 0x05) << "Reset goes first";
  EXPECT_EQ(frames_[1][4], 0x01);
  EXPECT_TRUE(sent_.back().reset_before);
  EXPECT_EQ(controller_.stats().timeout_errors_received, 1u);
}

TEST_F(BaseControllerTest, OwnSendingGapOfOneSecondForcesReset) {
  controller_.sendSpeed(t0_, false);
  frames_.clear();
  controller_.sendSpeed(t0_ + milliseconds(900), false);
  ASSERT_EQ(frames_.size(), 1u) << "0.9 s gap: the base has not timed out";
  controller_.sendSpeed(t0_ + milliseconds(1900), false);
  ASSERT_EQ(frames_.size(), 3u);
  EXPECT_EQ(frames_[1][4], 0x05);
}

TEST_F(BaseControllerTest, ReconnectForcesResetAndFailedWritesAreCounted) {
  controller_.sendSpeed(t0_, false);
  port_up_ = false;
  controller_.onLinkDown();
  controller_.sendSpeed(t0_ + milliseconds(20), false);
  EXPECT_EQ(controller_.stats().write_failures, 1u);
  port_up_ = true;
  controller_.onLinkUp();
  frames_.clear();
  controller_.sendSpeed(t0_ + milliseconds(40), false);
  ASSERT_EQ(frames_.size(), 2u);
  EXPECT_EQ(frames_[0][4], 0x05);
}

TEST_F(BaseControllerTest, ResetAndClearEncodersServicesWriteTheirFrames) {
  EXPECT_TRUE(controller_.sendClearEncoders());
  EXPECT_TRUE(controller_.sendReset());
  ASSERT_EQ(frames_.size(), 2u);
  EXPECT_EQ(frames_[0], (Bytes{0x55, 0xAA, 0x02, 0x00, 0x06, 0x00, 0xFB}));  // clear, SEQ 00
  EXPECT_EQ(frames_[1], (Bytes{0x55, 0xAA, 0x02, 0x01, 0x05, 0x00, 0xF9}));  // Reset, SEQ 01
  port_up_ = false;
  EXPECT_FALSE(controller_.sendReset());
}

TEST_F(BaseControllerTest, StopWritesAZeroSpeedFrame) {
  controller_.setCommand(0.5, 0.0);
  controller_.sendSpeed(Clock::now(), true);
  frames_.clear();
  controller_.stop();
  ASSERT_EQ(frames_.size(), 1u);
  EXPECT_EQ(frames_[0][4], 0x01);
  for (int i = 5; i < 13; ++i) EXPECT_EQ(frames_[0][i], 0) << "byte " << i;
}

TEST(BaseControllerBattery, PollsAtTheConfiguredRateAndReportsReplies) {
  BaseConfig config;
  config.battery_poll_rate = 1.0;
  std::vector<Bytes> frames;
  std::vector<int> percents;
  BaseEvents events;
  events.on_battery = [&percents](uint8_t p) { percents.push_back(p); };
  BaseController controller(
      config,
      [&frames](const Bytes& f) {
        frames.push_back(f);
        return true;
      },
      events);
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i <= 100; ++i) controller.tick(t0 + milliseconds(20 * i));  // 2 s
  int requests = 0;
  for (const Bytes& f : frames) requests += (f[4] == 0x02);
  EXPECT_GE(requests, 2);
  EXPECT_LE(requests, 3);
  // battery reply, 87 %, SEQ 00: 55^AA^02^00^02^57 = A8
  const Bytes reply = {0x55, 0xAA, 0x02, 0x00, 0x02, 0x57, 0xA8};
  controller.onFrame(protocol::FrameFamily::kBase, reply.data(), reply.size(), Clock::now());
  ASSERT_EQ(percents.size(), 1u);
  EXPECT_EQ(percents[0], 87);
}

class RecordingWriter {
 public:
  bool operator()(const Bytes& frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    frames_.push_back(frame);
    return true;
  }
  std::vector<Bytes> frames() {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }

 private:
  std::mutex mutex_;
  std::vector<Bytes> frames_;
};

TEST(BaseControllerLoop, RunningLoopKeepsTheHeartbeatAndStopsTheWheels) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  RecordingWriter writer;
  BaseController controller(config, std::ref(writer));
  controller.start();
  controller.setCommand(0.2, 0.0);
  std::this_thread::sleep_for(milliseconds(300));
  controller.stop();
  const std::vector<Bytes> frames = writer.frames();
  ASSERT_GE(frames.size(), 5u) << "about 15 ticks in 300 ms at 50 Hz";
  EXPECT_EQ(frames.front()[4], 0x05);
  bool moved = false;
  for (const Bytes& f : frames) moved |= (f[4] == 0x01 && f[6] > 0);
  EXPECT_TRUE(moved);
  EXPECT_EQ(frames.back()[4], 0x01);
  EXPECT_EQ(frames.back()[6], 0) << "the last frame stops the wheels";
}

TEST(BaseControllerLoop, NewCommandGoesOutBeforeTheNextTick) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  config.loop_rate = 0.5;  // the first tick is 2 s away: only a rushed frame can appear before it
  RecordingWriter writer;
  BaseController controller(config, std::ref(writer));
  controller.start();
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_TRUE(writer.frames().empty());
  controller.setCommand(0.2, 0.0);
  const auto deadline = Clock::now() + milliseconds(1500);
  while (writer.frames().size() < 2 && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(2));
  }
  const std::vector<Bytes> frames = writer.frames();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0][4], 0x05) << "Reset first";
  EXPECT_EQ(frames[1][4], 0x01);
  EXPECT_EQ(frames[1][6], 8) << "0.2 m/s = 8.15 ticks per period";
  EXPECT_EQ(controller.stats().immediate_frames, 1u);
  controller.stop();
}

}  // namespace
}  // namespace serial_robot_driver::device
