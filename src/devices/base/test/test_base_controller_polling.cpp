// BaseController polling the base: a base that goes silent, timeout errors, battery polls, and the
// loop on the real clock.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>

#include "support/base_controller_fixture.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::base {
namespace {

using namespace base_controller_test;  // NOLINT: the shared fixture

// --- the base going silent -------------------------------------------------------------------

TEST(BaseControllerSilence, UnansweredPollsMakeTheBaseSilentOnceUntilItAnswers) {
  BaseConfig config;
  config.battery_poll_rate = 1.0;
  int silent_events = 0;
  BaseEvents events;
  events.on_silent = [&silent_events](double) { ++silent_events; };
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  const auto started = startOnManualClock(config, events, clock);
  BaseController& controller = *started;
  clock->tick(150);  // 3 s: the first request went out at 1.02 s (the first tick sent the Reset)
  EXPECT_FALSE(controller.stats().base_silent);
  ASSERT_TRUE(controller.stats().seconds_without_reply.has_value());
  clock->tick(100);  // 5 s: more than 3 poll periods without a reply
  EXPECT_TRUE(controller.stats().base_silent);
  EXPECT_GT(*controller.stats().seconds_without_reply, 3.0);
  clock->tick(100);
  EXPECT_EQ(silent_events, 1) << "reported once, not every tick";
  // battery reply, 87 %, SEQ 00: 55^AA^02^00^02^57 = A8
  const Bytes& reply = golden::base::kBattery87ReplySeq0;
  controller.onFrame(kFrames, reply.data(), reply.size(), clock->now());
  EXPECT_FALSE(controller.stats().base_silent);
  controller.stop();
}

TEST_F(BaseControllerTest, TimeoutErrorWhileRunningIsCountedButNotTheOneAtStart) {
  // FF error status from the base, SEQ 07: 55^AA^02^07^FF^00 = 05
  const Bytes& error = golden::base::kErrorStatusSeq7;
  clock_->tick(1);  // Reset + first frame
  clock_->step([&] { controller_.onFrame(kFrames, error.data(), error.size(), clock_->now()); });
  EXPECT_EQ(controller_.stats().timeout_errors_while_running, 0u) << "in flight before our Reset";
  clock_->tick(100);  // 2 s of running
  clock_->step([&] { controller_.onFrame(kFrames, error.data(), error.size(), clock_->now()); });
  EXPECT_EQ(controller_.stats().timeout_errors_while_running, 1u);
  ASSERT_TRUE(controller_.stats().seconds_since_running_timeout_error.has_value());
  EXPECT_EQ(controller_.stats().timeout_errors_received, 2u);
}

TEST(BaseControllerBattery, PollsAtTheConfiguredRateAndReportsReplies) {
  BaseConfig config;
  config.battery_poll_rate = 1.0;
  std::vector<Bytes> frames;
  std::vector<int> percents;
  BaseEvents events;
  events.on_battery = [&percents](uint8_t p, core::Clock::time_point) { percents.push_back(p); };
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  const auto started = startOnManualClock(config, events, clock, &frames);
  BaseController& controller = *started;
  clock->tick(101);  // 2.02 s: the first tick sends the Reset instead, then one request per second
  int requests = 0;
  for (const Bytes& f : frames) requests += (f[4] == 0x02);
  EXPECT_EQ(requests, 2);
  EXPECT_EQ(controller.stats().battery_requests, 2u);
  // battery reply, 87 %, SEQ 00: 55^AA^02^00^02^57 = A8
  const Bytes& reply = golden::base::kBattery87ReplySeq0;
  controller.onFrame(kFrames, reply.data(), reply.size(), core::Clock::now());
  ASSERT_EQ(percents.size(), 1u);
  EXPECT_EQ(percents[0], 87);
  controller.stop();
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

TEST(BaseControllerLoop, ATickThatThrowsIsCountedAndTheHeartbeatGoesOn) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  RecordingWriter writer;
  std::atomic<int> odometry_reports{0};
  BaseEvents events;
  events.on_odometry = [&](const OdometrySample&) {
    if (++odometry_reports == 1) throw std::runtime_error("odom went wrong");
  };
  BaseController controller(config, std::ref(writer), events);
  controller.start();
  controller.setCommand(0.2, 0.0);
  ASSERT_TRUE(test_support::waitFor([&] { return odometry_reports >= 4; }, 3.0))
      << "the loop went on after the exception";
  const BaseStats stats = controller.stats();
  EXPECT_EQ(stats.internal_errors, 1u);
  EXPECT_EQ(stats.last_internal_error, "odom went wrong");
  EXPECT_GE(stats.speed_frames, 4u) << "a wheel frame every tick, the one that threw included";
  controller.stop();
  const std::vector<Bytes> frames = writer.frames();
  EXPECT_GT(frames[frames.size() - 2][6], 0) << "moving until the stop";
  EXPECT_EQ(frames.back()[6], 0) << "the stop's frame still goes out";
}

TEST(BaseControllerLoop, WithEveryTickThrowingTheEStopStillStopsTheWheelsAndVoidsTheCommand) {
  BaseConfig config;
  config.battery_poll_rate = 0;
  RecordingWriter writer;
  std::atomic<int> odometry_reports{0};
  BaseEvents events;
  events.on_odometry = [&](const OdometrySample&) {
    ++odometry_reports;
    throw std::runtime_error("odom always goes wrong");
  };
  BaseController controller(config, std::ref(writer), events);
  controller.start();
  controller.setCommand(0.2, 0.0);
  const auto moving = [&] {
    const std::vector<Bytes> frames = writer.frames();
    return !frames.empty() && frames.back()[4] == 0x01 && frames.back()[6] > 0;
  };
  ASSERT_TRUE(test_support::waitFor(moving, 3.0));
  controller.setEStop(true);
  const std::size_t at_e_stop = writer.frames().size();
  const int reports_at_e_stop = odometry_reports;
  ASSERT_TRUE(
      test_support::waitFor([&] { return odometry_reports >= reports_at_e_stop + 3; }, 3.0));
  controller.setEStop(false);  // released: the command accepted before it stays void
  const int reports_at_release = odometry_reports;
  ASSERT_TRUE(
      test_support::waitFor([&] { return odometry_reports >= reports_at_release + 3; }, 3.0));
  controller.stop();
  const std::vector<Bytes> frames = writer.frames();
  ASSERT_GT(frames.size(), at_e_stop + 1);
  // The e-stop's own frame may be the one written while setEStop() ran; every one after is zero.
  for (std::size_t i = at_e_stop + 1; i < frames.size(); ++i) {
    if (frames[i][4] == 0x01) EXPECT_EQ(frames[i][6], 0) << "frame " << i << " after the e-stop";
  }
  EXPECT_GE(controller.stats().internal_errors, 6u);
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
  const auto deadline = core::Clock::now() + milliseconds(1500);
  while (writer.frames().size() < 2 && core::Clock::now() < deadline) {
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
}  // namespace serial_robot_driver::devices::base
