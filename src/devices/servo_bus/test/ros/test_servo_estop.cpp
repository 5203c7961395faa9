// The bus servos' motion rules under the e-stop (servo_estop.test), against robot_sim on a slow
// bus (2 s timeout, 3 retries) behind a tap that records every frame the node writes: a slow
// rotate whose first stop is lost is still stopped; a spin accepted before an e-stop never goes
// out after its release; a stop engaged and released while the cable is out goes out after the
// replug; broadcast motions are refused; a moving servo keeps its address, a resting one's stop
// follows it to its new one; relax works under the e-stop and is not undone by its stops.
// Golden frames by hand from docs/protocols.md (SPIN: 12 4C 07 06 | id, method, speed u16,
// value u16 | sum of the bytes before it).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "support/servo_bus_node_support.h"

namespace {

using namespace servo_bus_node_test;  // NOLINT: the simulated bus behind its tap, the SPIN frames

constexpr double kWaitSeconds = 20.0;
constexpr char kNode[] = "driver_node";
constexpr uint8_t kSpinCmd = 0x07;
constexpr uint8_t kReadAngleCmd = 0x0A;

srd::ServoWrite writeCall(uint8_t id, const std::string& param, int64_t value) {
  srd::ServoWrite call;
  call.request.id = id;
  call.request.param = param;
  call.request.value = value;
  EXPECT_TRUE(test_support::callService("servo/write", call));
  return call;
}

std::size_t countWhere(const std::vector<PtyTap::Frame>& frames, std::size_t from,
                       const std::function<bool(const Bytes&)>& match) {
  return static_cast<std::size_t>(
      std::count_if(frames.begin() + static_cast<long>(std::min(from, frames.size())), frames.end(),
                    [&](const PtyTap::Frame& f) { return f.bytes.size() > 5 && match(f.bytes); }));
}

class ServoEStop : public SimBusTest {
 protected:
  ServoEStop() : SimBusTest(kNode, kWaitSeconds) {}
};

// First in the file: the simulator loses the first SPIN stop (--lose-servo-stops 1). Servo 1
// turns at 1.5 deg/s: two looks 0.1 s apart cannot tell it from rest. The e-stop's stop is written
// again while it holds, so the servo stops under the e-stop.
TEST_F(ServoEStop, ASlowRotateWhoseFirstStopIsLostIsStillStoppedUnderTheEStop) {
  ASSERT_TRUE(waitFor([&] { return simServo(1).has_value(); }, kWaitSeconds));
  srd::ServoRotate rotate;
  rotate.request.id = 1;
  const double from_deg = simServo(1)->angle_deg;
  rotate.request.angle_deg = from_deg > 0.0 ? from_deg - 60.0 : from_deg + 60.0;
  rotate.request.interval_ms = 40000;  // 1.5 deg/s
  ASSERT_TRUE(waitFor(
      [&] { return test_support::callService("servo/rotate", rotate) && rotate.response.success; },
      kWaitSeconds));
  ASSERT_TRUE(waitMoving(1, true));
  setEStop(true);
  ASSERT_TRUE(waitMoving(1, false)) << "the slow servo still turns under the e-stop";
  EXPECT_EQ(srd::devices::servo_bus::sim::servoBusStats(g_robot->stats()).stops_lost, 1u);
  EXPECT_GE(count(g_bus->frames(), kSpin1StopSpeed0), 2u);
}

// The user's report: a servo/read of an absent servo holds the bus for 4 x 2 s; a servo/spin
// waits behind it; the e-stop is engaged and released a second later. The spin was accepted
// before the e-stop: it never reaches the wire, and its call says why.
TEST_F(ServoEStop, ASpinAcceptedBeforeAnEStopIsNotWrittenAfterItsRelease) {
  const std::size_t spins_before = count(g_bus->frames(), kSpin1Continuous90);
  ASSERT_TRUE(holdTheBusWithAReadOfServo7());
  srd::ServoSpin spin;
  std::thread mover([&] { spin = spinCall(1, 1); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the spin is waiting for the bus
  setEStop(true);
  std::this_thread::sleep_for(std::chrono::seconds(1));
  setEStop(false);
  mover.join();
  reader_.join();
  EXPECT_FALSE(spin.response.success);
  EXPECT_NE(spin.response.message.find("e-stop engaged after this command was accepted"),
            std::string::npos)
      << spin.response.message;
  EXPECT_EQ(count(g_bus->frames(), kSpin1Continuous90), spins_before)
      << "a SPIN accepted before the e-stop was written after its release";
  EXPECT_FALSE(simServo(1)->moving);
}

// Engaged and released while the cable is out: the stop never went out, so the release keeps it
// and it is the first frame after the replug.
TEST_F(ServoEStop, AStopEngagedAndReleasedWhileUnpluggedGoesOutAfterTheReplug) {
  spinServo(1);
  ASSERT_TRUE(pullTheCable());
  setEStop(true);
  setEStop(false);
  ASSERT_TRUE(plugTheCableBack());
  EXPECT_EQ(g_bus->frames().front().bytes, kSpin1StopSpeed0) << "the stop is the first frame";
  EXPECT_TRUE(waitMoving(1, false)) << "the release dropped the stop never written";
}

// Nothing answers a broadcast: refused, with a message, and nothing on the wire.
TEST_F(ServoEStop, ABroadcastSpinIsRefused) {
  const std::size_t before = g_bus->frameCount();
  const srd::ServoSpin spin = spinCall(255, 1);
  EXPECT_FALSE(spin.response.success);
  EXPECT_NE(spin.response.message.find("broadcast"), std::string::npos) << spin.response.message;
  EXPECT_EQ(countWhere(g_bus->frames(), before,
                       [](const Bytes& b) {
                         return b[2] == kSpinCmd && b[4] == 0xFF && (b[5] & 0x7F) != 0;
                       }),
            0u);
  for (uint8_t id = 0; id <= 3; ++id) EXPECT_FALSE(simServo(id)->moving) << "servo " << int(id);
}

// A moving servo keeps its address; once stopped it may change it, and the e-stop's stop goes
// to the new address, not the old, empty one.
TEST_F(ServoEStop, AnAddressChangeIsRefusedWhileTheServoMovesAndTakesItsStopAlongAtRest) {
  spinServo(2);
  const srd::ServoWrite refused = writeCall(2, "servo_id", 6);
  EXPECT_FALSE(refused.response.success);
  EXPECT_NE(refused.response.message.find("while it moves"), std::string::npos)
      << refused.response.message;
  ASSERT_TRUE(simServo(2).has_value()) << "the moving servo changed its address";

  ASSERT_TRUE(spinCall(2, 0).response.success);
  ASSERT_TRUE(waitMoving(2, false));
  const srd::ServoWrite changed = writeCall(2, "servo_id", 6);
  ASSERT_TRUE(changed.response.success) << changed.response.message;
  ASSERT_TRUE(simServo(6).has_value());
  const std::size_t before = g_bus->frameCount();
  setEStop(true);
  ASSERT_TRUE(g_bus->waitForFrames(
      [&](const auto& frames) { return count(frames, kSpin6StopSpeed0, before) >= 1; },
      kWaitSeconds))
      << "the stop did not follow the servo to its new address";
  EXPECT_EQ(count(g_bus->frames(), kSpin2StopSpeed0, before), 0u);
  const srd::ServoWrite locked = writeCall(6, "servo_id", 2);
  EXPECT_FALSE(locked.response.success) << "an address change under the e-stop";
  EXPECT_NE(locked.response.message.find("e_stop"), std::string::npos) << locked.response.message;
  setEStop(false);
  const srd::ServoWrite back = writeCall(6, "servo_id", 2);
  EXPECT_TRUE(back.response.success) << back.response.message;
}

// Torque off is a safety action: allowed under the e-stop, and the e-stop's repeated stops leave
// the relaxed servo relaxed (watched over ten of the state polls of servo 1, ~2 s).
TEST_F(ServoEStop, RelaxIsAllowedUnderTheEStopAndTheStopsDoNotUndoIt) {
  spinServo(1);
  setEStop(true);
  ASSERT_TRUE(waitMoving(1, false));
  srd::ServoRelax relax;
  relax.request.ids = {1};
  ASSERT_TRUE(test_support::callService("servo/relax", relax));
  EXPECT_TRUE(relax.response.success) << relax.response.message;
  ASSERT_TRUE(waitFor([&] { return simServo(1)->relaxed; }, kWaitSeconds));
  const std::size_t relaxed_at = g_bus->frameCount();
  const auto polls_of_1 = [&](const std::vector<PtyTap::Frame>& frames) {
    return countWhere(frames, relaxed_at,
                      [](const Bytes& b) { return b[2] == kReadAngleCmd && b[4] == 1; });
  };
  ASSERT_TRUE(g_bus->waitForFrames([&](const auto& frames) { return polls_of_1(frames) >= 10; },
                                   kWaitSeconds));
  EXPECT_EQ(count(g_bus->frames(), kSpin1StopSpeed0, relaxed_at), 0u);
  EXPECT_TRUE(simServo(1)->relaxed);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_estop");
  return runAllTestsOnSimBus(firstStopLostOptions(kNode), test_support::nodeParam(kNode, "port"));
}
