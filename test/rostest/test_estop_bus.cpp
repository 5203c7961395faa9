// The e-stop under the conditions of the field (estop_bus.test): a busy bus (a slow transaction
// with a motion waiting behind it, a long scan), a loose cable and a stop the line loses. The
// simulated robot (sim::RobotSim, this process) plays the base and the bus servos on ports of
// their own; a tap between the node and each records every frame the node writes, so the test
// sees what went on the wire and in which order. Golden frames are written out by hand from
// docs/protocols.md. No timing assertions but one gap bound far above the base's 20 ms period
// (a callback held by the bus would show as seconds).
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the simulated bus behind its tap, the SPIN frames

constexpr double kWaitSeconds = 20.0;
constexpr char kNode[] = "driver_node";
constexpr uint8_t kPingCmd = 0x01;

PtyTap* g_base = nullptr;

class EStopBus : public SimBusTest {
 protected:
  EStopBus() : SimBusTest(kNode, kWaitSeconds) {}
};

// First in the file: the simulator loses the first SPIN stop it is sent (--lose-servo-stops 1).
// The cable is out when the e-stop comes; after the replug the stop is the first frame on the bus;
// the line loses it, the servo still turns, and the node writes it again until the servo rests.
TEST_F(EStopBus, AStopEngagedWhileUnpluggedGoesFirstAfterTheReplugAndAgainWhenLost) {
  spinServo(1);
  ASSERT_TRUE(pullTheCable());
  setEStop(true);
  const auto unconfirmed = diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.value("stops not yet confirmed").find("servo_1") == 0; },
      [] { return ros::ok(); }, kWaitSeconds);
  ASSERT_TRUE(unconfirmed.has_value());
  EXPECT_EQ(unconfirmed->level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_NE(unconfirmed->message.find("servo_1"), std::string::npos) << unconfirmed->message;
  EXPECT_TRUE(simServo(1)->moving) << "nothing can reach the servo while the cable is out";

  ASSERT_TRUE(plugTheCableBack());
  EXPECT_EQ(g_bus->frames().front().bytes, kSpin1StopSpeed0) << "the stop is the first frame";
  ASSERT_TRUE(waitMoving(1, false)) << "the lost stop was never written again";
  EXPECT_EQ(srd::devices::servo_bus::sim::servoBusStats(g_robot->stats()).stops_lost, 1u);
  EXPECT_GE(count(g_bus->frames(), kSpin1StopSpeed0), 2u);
  EXPECT_TRUE(diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.value("stops not yet confirmed") == "none"; },
      [] { return ros::ok(); }, kWaitSeconds));
}

// The user's report: a servo/read of an absent servo holds the bus for timeout * 4 = 2 s; a
// servo/spin waits behind it; the e-stop comes. The spin must never reach the wire.
TEST_F(EStopBus, AMotionWaitingBehindASlowTransactionIsRefusedWhenTheEStopComes) {
  const std::size_t spins_before = count(g_bus->frames(), kSpin1Continuous90);
  ASSERT_TRUE(holdTheBusWithAReadOfServo7());
  srd::ServoSpin spin;
  std::thread mover([&] {
    spin.request.id = 1;
    spin.request.mode = 1;
    spin.request.speed_dps = 90;
    test_support::callService("servo/spin", spin);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the spin is waiting for the bus
  EXPECT_EQ(count(g_bus->frames(), kSpin1Continuous90), spins_before);
  setEStop(true);
  mover.join();
  reader_.join();
  EXPECT_FALSE(spin.response.success);
  EXPECT_NE(spin.response.message.find("e_stop"), std::string::npos) << spin.response.message;
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // anything late would be out now
  EXPECT_EQ(count(g_bus->frames(), kSpin1Continuous90), spins_before)
      << "a SPIN was written after the e-stop";
  EXPECT_FALSE(simServo(1)->moving);
  const auto status = diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.number("motion frames refused when written") >= 1; },
      [] { return ros::ok(); }, kWaitSeconds);
  EXPECT_TRUE(status.has_value()) << "the refusal at the write is not counted";
}

// The e-stop during a long servo/scan (one 0.5 s PING per absent id): the stop is on the wire
// after at most the one PING in flight, not after the scan; the base keeps its 50 Hz pace.
TEST_F(EStopBus, AStopDuringALongScanWaitsForOneTransactionAndTheBaseKeepsItsPace) {
  spinServo(1);
  srd::ServoScan scan;
  scan.request.first_id = 10;
  scan.request.last_id = 25;  // absent: 16 x 0.5 s
  std::thread scanner([&] { test_support::callService("servo/scan", scan); });
  ASSERT_TRUE(g_bus->waitForFrames(
      [](const auto& frames) {
        return !frames.empty() && frames.back().bytes[2] == kPingCmd &&
               frames.back().bytes[4] >= 11;
      },
      kWaitSeconds));
  const std::size_t at_e_stop = g_bus->frameCount();
  const auto engaged_at = std::chrono::steady_clock::now();
  setEStop(true);
  ASSERT_TRUE(g_bus->waitForFrames(
      [&](const auto& frames) { return count(frames, kSpin1StopSpeed0, at_e_stop) >= 1; },
      kWaitSeconds));
  const std::vector<PtyTap::Frame> frames = g_bus->frames();
  std::size_t pings_before_stop = 0;
  for (std::size_t i = at_e_stop; i < frames.size() && frames[i].bytes != kSpin1StopSpeed0; ++i) {
    pings_before_stop += frames[i].bytes[2] == kPingCmd ? 1 : 0;
  }
  EXPECT_LE(pings_before_stop, 1u) << "the stop waited for the scan";
  ASSERT_TRUE(waitMoving(1, false));
  std::this_thread::sleep_for(std::chrono::seconds(1));
  // The base's frames around the e-stop: no gap anywhere near the bus's waits.
  const std::vector<PtyTap::Frame> base = g_base->frames();
  double longest_gap_s = 0.0;
  for (std::size_t i = 1; i < base.size(); ++i) {
    if (base[i].arrival < engaged_at - std::chrono::seconds(1)) continue;
    longest_gap_s =
        std::max(longest_gap_s,
                 std::chrono::duration<double>(base[i].arrival - base[i - 1].arrival).count());
  }
  EXPECT_LT(longest_gap_s, 0.5) << "the base's loop was held up";
  scanner.join();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_estop_bus");
  return runAllTestsOnSimBus(firstStopLostOptions(kNode), test_support::nodeParam(kNode, "port"),
                             &g_base);
}
