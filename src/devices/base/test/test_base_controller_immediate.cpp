// BaseController: a cmd_vel's wheel frame written at once by the thread that delivers it, under the
// loop's lock, so the loop and the immediate writes never interleave, and an e-stop engaged before
// a write means no motion frame.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "support/base_controller_fixture.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::base {
namespace {

using namespace base_controller_test;  // NOLINT: the shared fixture

/// Every frame written to the fake port, with the thread that wrote it and whether the test had
/// the e-stop engaged (set once setEStop(true) returned, cleared before setEStop(false)).
class WireLog {
 public:
  struct Written {
    Bytes frame;
    std::thread::id thread;
    bool under_e_stop = false;
  };

  bool write(const Bytes& frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    written_.push_back({frame, std::this_thread::get_id(), e_stop_engaged.load()});
    return true;
  }
  std::vector<Written> written() {
    std::lock_guard<std::mutex> lock(mutex_);
    return written_;
  }

  std::atomic<bool> e_stop_engaged{false};

 private:
  std::mutex mutex_;
  std::vector<Written> written_;
};

// Speed frame (docs/protocols.md): 55 AA 09 SEQ 01, then left and right ticks, 8 bytes.
bool isSpeedFrame(const Bytes& frame) { return frame.size() >= 13 && frame[4] == 0x01; }

bool isMotionFrame(const Bytes& frame) {
  if (!isSpeedFrame(frame)) return false;
  for (std::size_t i = 5; i < 13; ++i) {
    if (frame[i] != 0) return true;
  }
  return false;
}

std::unique_ptr<BaseController> controllerWritingTo(WireLog& log, const BaseConfig& config,
                                                    std::shared_ptr<core::LoopClock> clock = {}) {
  return std::make_unique<BaseController>(
      config, [&log](const Bytes& frame) { return log.write(frame); }, BaseEvents{},
      std::move(clock));
}

BaseConfig quietConfig() {
  BaseConfig config;
  config.battery_poll_rate = 0;
  return config;
}

/// quietConfig() on a 4 Mbaud line, where an immediate frame may follow the last after ~70 us.
BaseConfig fastLineConfig(double loop_rate, double cmd_vel_timeout) {
  BaseConfig config = quietConfig();
  config.loop_rate = loop_rate;
  config.baud = 4000000;
  config.cmd_vel_timeout = cmd_vel_timeout;
  return config;
}

TEST(BaseControllerImmediate, ACmdVelIsWrittenByItsCallerBeforeTheCallReturns) {
  WireLog log;
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  auto controller = controllerWritingTo(log, quietConfig(), clock);
  controller->start();
  clock->waitForLoop();
  EXPECT_EQ(controller->submitCommand(0.2, 0.0), CommandOutcome::kSent);
  const std::vector<WireLog::Written> written = log.written();
  ASSERT_EQ(written.size(), 2u) << "the Reset and the speed frame, before the call returned";
  EXPECT_EQ(written[0].frame[4], 0x05);
  EXPECT_EQ(written[1].frame[4], 0x01);
  EXPECT_EQ(written[1].frame[6], 8) << "0.2 m/s = 8.15 ticks per period";
  for (const WireLog::Written& w : written) EXPECT_EQ(w.thread, std::this_thread::get_id());
  controller->stop();
}

TEST(BaseControllerImmediate, NoCmdVelIsWrittenAfterTheLastWords) {
  WireLog log;
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  auto controller = controllerWritingTo(log, quietConfig(), clock);
  controller->start();
  clock->waitForLoop();
  controller->stop();
  const std::size_t last_words = log.written().size();
  ASSERT_GT(last_words, 0u);
  EXPECT_NE(controller->submitCommand(0.5, 0.0), CommandOutcome::kSent);
  EXPECT_EQ(log.written().size(), last_words) << "the zero frame of stop() stays the last";
}

TEST(BaseControllerImmediate, AnEStopEngagedBeforeTheWriteMeansNoMotionFrame) {
  WireLog log;
  auto clock = std::make_shared<core::ManualClock>(core::Clock::now());
  auto controller = controllerWritingTo(log, quietConfig(), clock);
  controller->start();
  clock->waitForLoop();
  const BaseController::Generation accepted = controller->generation();
  clock->step([&] { controller->setEStop(true); });  // between the acceptance and the write
  log.e_stop_engaged = true;
  EXPECT_EQ(controller->submitCommand(0.5, 0.0, accepted), CommandOutcome::kEStopEngaged);
  log.e_stop_engaged = false;
  clock->step([&] { controller->setEStop(false); });
  EXPECT_EQ(controller->submitCommand(0.5, 0.0, accepted), CommandOutcome::kVoided);
  clock->tick(5);
  for (const WireLog::Written& w : log.written()) EXPECT_FALSE(isMotionFrame(w.frame));
  controller->stop();
}

// The real clock, a 1 kHz loop and a fast line, so the loop's ticks, the commands written by their
// caller and the e-stop's zero frames race each other for the port.
TEST(BaseControllerImmediate, CommandsRacingTheLoopAndTheEStopKeepOneSequenceAndStopWhenTold) {
  const BaseConfig config = fastLineConfig(1000.0, 5.0);
  WireLog log;
  auto controller = controllerWritingTo(log, config);
  controller->start();
  std::atomic<bool> done{false};
  std::thread e_stop([&] {
    for (int i = 0; i < 300; ++i) {
      controller->setEStop(true);
      log.e_stop_engaged = true;
      std::this_thread::sleep_for(std::chrono::microseconds(300));
      log.e_stop_engaged = false;
      controller->setEStop(false);
      std::this_thread::sleep_for(std::chrono::microseconds(300));
    }
    done = true;
  });
  for (int k = 0; !done; ++k) {
    const BaseController::Generation accepted = controller->generation();
    controller->submitCommand(0.3, 0.1 * (k % 3), accepted);
  }
  e_stop.join();
  const std::vector<WireLog::Written> written = log.written();  // not stop()'s zero frame
  controller->stop();

  std::size_t by_caller = 0, motion = 0;
  for (std::size_t i = 0; i < written.size(); ++i) {
    const Bytes& frame = written[i].frame;
    if (i > 0) {
      ASSERT_EQ(frame[3], static_cast<uint8_t>(written[i - 1].frame[3] + 1))
          << "SEQ of frame " << i << ": one sequence, no frame written twice or interleaved";
    }
    EXPECT_FALSE(written[i].under_e_stop && isMotionFrame(frame)) << "frame " << i;
    by_caller += written[i].thread == std::this_thread::get_id();
    motion += isMotionFrame(frame);
  }
  EXPECT_GT(by_caller, 0u) << "commands were written by their caller";
  EXPECT_LT(by_caller, written.size()) << "and the loop wrote too";
  EXPECT_GT(motion, 0u) << "between the e-stops the robot was driven";
}

// The real clock and a loop too slow to cover for a lost wake-up (one tick in 10 s): each e-stop
// wakes the loop (core::LoopWake), which writes the zero frame at once, cycle after cycle, each
// after a motion frame its caller wrote. A wake-up lost would leave the wheels turning until the
// tick.
TEST(BaseControllerImmediate, EachEStopWakesTheLoopToWriteTheZeroFrameWithoutWaitingForATick) {
  const BaseConfig config = fastLineConfig(0.1, 60.0);
  WireLog log;
  auto controller = controllerWritingTo(log, config);
  controller->start();
  const std::thread::id caller = std::this_thread::get_id();
  auto zeroFramesByTheLoop = [&] {
    std::size_t count = 0;
    for (const WireLog::Written& written : log.written()) {
      count += isSpeedFrame(written.frame) && !isMotionFrame(written.frame) &&
               written.thread != caller;
    }
    return count;
  };
  for (std::size_t cycle = 1; cycle <= 20; ++cycle) {
    ASSERT_TRUE(test_support::waitFor(
        [&] {
          return controller->submitCommand(0.3, 0.0, controller->generation()) ==
                 CommandOutcome::kSent;
        },
        4.0))
        << "cycle " << cycle << ": the command was not written by its caller";
    controller->setEStop(true);
    ASSERT_TRUE(test_support::waitFor([&] { return zeroFramesByTheLoop() >= cycle; }, 4.0))
        << "cycle " << cycle << ": no zero frame from the loop before its tick";
    controller->setEStop(false);
  }
  controller->stop();
}

// The loop and a cmd_vel's caller both write frames; every front end (wheel_command, the DDS
// graph) still hears of them once each, in the order they went out.
TEST(BaseControllerImmediate, WrittenFramesAreReportedOnceEachInWriteOrderWhileTheLoopRaces) {
  const BaseConfig config = fastLineConfig(1000.0, 5.0);
  WireLog log;
  std::mutex reported_mutex;
  std::vector<uint8_t> reported;
  BaseEvents events;
  events.on_wheel_frame = [&](const WheelFrameSent& sent) {
    std::this_thread::yield();  // widen the window between the write and its report
    std::lock_guard<std::mutex> lock(reported_mutex);
    reported.push_back(sent.seq);
  };
  auto controller = std::make_unique<BaseController>(
      config, [&log](const Bytes& frame) { return log.write(frame); }, std::move(events));
  controller->start();
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(300);
  for (int k = 0; std::chrono::steady_clock::now() < until; ++k) {
    controller->submitCommand(0.3, 0.1 * (k % 3), controller->generation());
  }
  controller->stop();

  const std::vector<WireLog::Written> written = log.written();
  std::vector<uint8_t> written_speed_seqs;
  for (const WireLog::Written& w : written) {
    if (w.frame.size() >= 5 && w.frame[4] == 0x01) written_speed_seqs.push_back(w.frame[3]);
  }
  std::lock_guard<std::mutex> lock(reported_mutex);
  EXPECT_EQ(reported, written_speed_seqs);
}

}  // namespace
}  // namespace serial_robot_driver::devices::base
