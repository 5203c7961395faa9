// A stop waits for at most one bus transaction attempt, from every service (bus_yield.test), on a
// slow bus: a 0.5 s answer timeout, 3 retries, absent servos. The simulated bus servos 1 and 2
// (sim::RobotSim, this process) sit behind a tap that records every frame the node writes, so the
// test checks the order on the wire, never a duration:
//  - a stop (servo/spin mode 0, the e-stop) asked during servo/reset_user_data of an absent servo
//    (RESET_USER_DATA, PING 0, four times over under one call) goes out after at most one of its
//    frames;
//  - with both general service threads held by long calls (a scan of absent ids, a rotate waiting
//    for its completion), servo/spin mode 0 and servo/relax answer before the scan ends.
// Frames are written out by hand from docs/protocols.md, section 3 (SUM = byte sum mod 256).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the simulated bus behind its tap, the SPIN frames

constexpr double kWaitSeconds = 30.0;
constexpr char kNode[] = "driver_node";

// RESET_USER_DATA id 7 (CMD 2): 12+4C+02+01+07 = 0x68. Nobody answers at 7, nor at 0 after it
// (kPing0: the reset's check that the servo moved to id 0).
const Bytes kResetUserData7 = {0x12, 0x4C, 0x02, 0x01, 0x07, 0x68};
// Request bytes: 12 4C CMD N ID ...
constexpr std::size_t kCmdByte = 2;
constexpr std::size_t kIdByte = 4;
constexpr uint8_t kPingCmd = 0x01;
constexpr uint8_t kRotateCmd = 0x08;
constexpr uint8_t kDampingCmd = 0x09;
constexpr uint8_t kScanFirst = 10;
constexpr uint8_t kScanLast = 25;  // 16 absent ids: 16 timeouts of 0.5 s

bool isFrame(const PtyTap::Frame& frame, uint8_t cmd, uint8_t id) {
  return frame.bytes.size() > kIdByte && frame.bytes[kCmdByte] == cmd && frame.bytes[kIdByte] == id;
}

/// Where the first frame after `from` that `match` accepts was written; frames.size() when none.
std::size_t indexOf(const std::vector<PtyTap::Frame>& frames, std::size_t from,
                    const std::function<bool(const PtyTap::Frame&)>& match) {
  for (std::size_t i = from; i < frames.size(); ++i) {
    if (match(frames[i])) return i;
  }
  return frames.size();
}

/// Waits until a frame after `from` that `match` accepts is on the wire; its index.
std::size_t waitForFrame(std::size_t from, const std::function<bool(const PtyTap::Frame&)>& match) {
  EXPECT_TRUE(g_bus->waitForFrames(
      [&](const auto& frames) { return indexOf(frames, from, match) < frames.size(); },
      kWaitSeconds));
  return indexOf(g_bus->frames(), from, match);
}

/// A service call on a thread of its own; done() once it answered.
template <typename Service>
class Background {
 public:
  Background(std::string name, Service call) : call_(std::move(call)) {
    thread_ = std::thread([this, name = std::move(name)] {
      test_support::callService(name, call_);
      done_ = true;
    });
  }
  ~Background() { join(); }
  bool done() const { return done_; }
  const Service& join() {
    if (thread_.joinable()) thread_.join();
    return call_;
  }

 private:
  Service call_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

std::unique_ptr<Background<srd::ServoResetUserData>> resetAbsentServo() {
  srd::ServoResetUserData reset;
  reset.request.id = 7;
  const std::size_t before = g_bus->frameCount();
  auto call = std::make_unique<Background<srd::ServoResetUserData>>("servo/reset_user_data", reset);
  waitForFrame(before, [](const PtyTap::Frame& f) { return f.bytes == kResetUserData7; });
  return call;
}

/// The frames of reset_user_data's chain (its RESETs and PINGs of id 0) in [from, to).
std::size_t resetFramesBetween(std::size_t from, std::size_t to) {
  const std::vector<PtyTap::Frame> frames = g_bus->frames();
  return static_cast<std::size_t>(std::count_if(
      frames.begin() + static_cast<long>(from), frames.begin() + static_cast<long>(to),
      [](const PtyTap::Frame& f) { return f.bytes == kResetUserData7 || f.bytes == kPing0; }));
}

class BusYield : public SimBusTest {
 protected:
  BusYield() : SimBusTest(kNode, kWaitSeconds) {}
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(waitForTheNode());
    // The services come up before the port opens.
    ASSERT_TRUE(waitFor([&] { return spinCall(1, 0).response.success; }, kWaitSeconds));
  }
};

// The report: reset_user_data ran its RESET / PING 0 chain under one bus lock and a stop
// waited for all of it (8 transactions of 0.5 s here). A manual stop goes after the one in flight.
TEST_F(BusYield, AManualStopGoesBeforeTheRestOfAResetUserData) {
  auto reset = resetAbsentServo();
  const std::size_t asked = g_bus->frameCount();
  EXPECT_TRUE(spinCall(1, 0).response.success);
  const std::size_t stop =
      waitForFrame(asked, [](const PtyTap::Frame& f) { return f.bytes == kSpin1StopSpeed0; });
  EXPECT_LE(resetFramesBetween(asked, stop), 1u) << "the stop waited for the reset's chain";
  EXPECT_FALSE(reset->join().response.success) << "nothing answers at id 7 or 0";
  EXPECT_GT(resetFramesBetween(stop, g_bus->frameCount()), 0u) << "the reset went on after it";
}

// The same with the e-stop: its stop of the spinning servo goes before the rest of the chain.
TEST_F(BusYield, TheEStopsStopGoesBeforeTheRestOfAResetUserData) {
  ASSERT_TRUE(spinCall(1, 1).response.success);
  auto reset = resetAbsentServo();
  const std::size_t asked = g_bus->frameCount();
  setEStop(true);
  const std::size_t stop =
      waitForFrame(asked, [](const PtyTap::Frame& f) { return f.bytes == kSpin1StopSpeed0; });
  EXPECT_LE(resetFramesBetween(asked, stop), 1u) << "the stop waited for the reset's chain";
  reset->join();
}

// Both general service threads are held: one by a scan of 16 absent ids, one by a rotate waiting
// for its completion (20 s). servo/spin mode 0 and servo/relax run on the stop thread anyway, and
// their frames go out before the scan's last PING.
TEST_F(BusYield, StopServicesAnswerWhileTwoLongCallsHoldTheOtherThreads) {
  const std::vector<std::pair<const char*, std::function<bool()>>> stop_calls = {
      {"servo/spin mode 0", [] { return spinCall(1, 0).response.success; }},
      {"servo/relax", [] {
         srd::ServoRelax relax;
         relax.request.ids = {1};
         return test_support::callService("servo/relax", relax) && relax.response.success;
       }}};
  const std::vector<std::function<bool(const PtyTap::Frame&)>> stop_frames = {
      [](const PtyTap::Frame& f) { return f.bytes == kSpin1StopSpeed0; },
      [](const PtyTap::Frame& f) { return isFrame(f, kDampingCmd, 1); }};
  for (std::size_t i = 0; i < stop_calls.size(); ++i) {
    SCOPED_TRACE(stop_calls[i].first);
    const std::size_t start = g_bus->frameCount();
    srd::ServoScan scan_call;
    scan_call.request.first_id = kScanFirst;
    scan_call.request.last_id = kScanLast;
    Background<srd::ServoScan> scan("servo/scan", scan_call);
    waitForFrame(start, [](const PtyTap::Frame& f) { return isFrame(f, kPingCmd, kScanFirst); });
    srd::ServoRotate rotate_call;
    rotate_call.request.id = 2;
    rotate_call.request.angle_deg = 90.0 * static_cast<double>(i + 1);
    rotate_call.request.interval_ms = 20000;
    rotate_call.request.wait = true;
    Background<srd::ServoRotate> rotate("servo/rotate", rotate_call);
    waitForFrame(start, [](const PtyTap::Frame& f) { return isFrame(f, kRotateCmd, 2); });

    EXPECT_TRUE(stop_calls[i].second());
    EXPECT_FALSE(scan.done()) << "the stop call answered only after the scan";
    scan.join();
    const std::vector<PtyTap::Frame> frames = g_bus->frames();
    EXPECT_LT(indexOf(frames, start, stop_frames[i]),
              indexOf(frames, start,
                      [](const PtyTap::Frame& f) { return isFrame(f, kPingCmd, kScanLast); }))
        << "the stop went out after the scan";
    EXPECT_FALSE(rotate.join().response.success) << "the rotate's wait gave way to the stop";
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_bus_yield");
  sim::SimOptions options = simBusOptions(test_support::nodeParam(kNode, "port"), {1, 2});
  options.device("base").enabled = false;
  srd::devices::servo_bus::sim::servoBusConfig(options).response_switch = {{2, 1}};
  return runAllTestsOnSimBus(options);
}
