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
#include <std_msgs/Bool.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/pty_tap.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::PtyTap;
using test_support::waitFor;
using Bytes = std::vector<uint8_t>;

constexpr double kWaitSeconds = 20.0;
constexpr char kNode[] = "driver_node";

// SPIN (CMD 7, content id, method, speed u16, value u16), checksum = sum of the bytes before it.
// Servo 1 counter-clockwise continuous at 90 deg/s: 12+4C+07+06+01+01+5A = 0xC7.
const Bytes kSpin1Continuous90 = {0x12, 0x4C, 0x07, 0x06, 0x01, 0x01, 0x5A, 0x00, 0x00, 0x00, 0xC7};
// Servo 1 stop (mode 0, speed 0): 12+4C+07+06+01 = 0x6C.
const Bytes kSpin1Stop = {0x12, 0x4C, 0x07, 0x06, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x6C};
constexpr uint8_t kPingCmd = 0x01;

sim::RobotSim* g_robot = nullptr;
std::unique_ptr<PtyTap>* g_bus = nullptr;
PtyTap* g_base = nullptr;
std::string g_bus_port;
std::string g_bus_sim_port;

std::unique_ptr<PtyTap> plugBus() {
  srd::protocol::FramerConfig framer;
  framer.accept(serial_robot_driver::protocol::servo::kRequestFrames);
  return std::make_unique<PtyTap>(g_bus_port, g_bus_sim_port, framer);
}

std::optional<sim::BusServoSnapshot> simServo(uint8_t id) {
  for (const sim::BusServoSnapshot& servo : servoBusStats(g_robot->stats()).servos) {
    if (servo.id == id) return servo;
  }
  return std::nullopt;
}

bool waitMoving(uint8_t id, bool moving) {
  return waitFor([&] { return simServo(id) && simServo(id)->moving == moving; }, kWaitSeconds);
}

srd::ServoSpin spinCall(uint8_t id, uint8_t mode) {
  srd::ServoSpin call;
  call.request.id = id;
  call.request.mode = mode;
  call.request.speed_dps = mode == 0 ? 0 : 90;
  EXPECT_TRUE(ros::service::call("servo/spin", call));
  return call;
}

std::size_t count(const std::vector<PtyTap::Frame>& frames, const Bytes& bytes,
                  std::size_t from = 0) {
  return static_cast<std::size_t>(
      std::count_if(frames.begin() + static_cast<long>(std::min(from, frames.size())), frames.end(),
                    [&](const PtyTap::Frame& f) { return f.bytes == bytes; }));
}

class EStopBus : public ::testing::Test {
 protected:
  EStopBus() : diagnostics_(nh_, kNode) {
    e_stop_ = nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true);
  }
  void SetUp() override {
    ASSERT_TRUE(waitFor([&] { return e_stop_.getNumSubscribers() > 0; }, kWaitSeconds));
    ASSERT_TRUE(ros::service::waitForService("servo/spin", 30000));
    setEStop(false);
  }
  void TearDown() override {
    setEStop(false);
    spinCall(1, 0);
  }
  void setEStop(bool engaged) {
    ASSERT_TRUE(test_support::setEStopAndWait(e_stop_, diagnostics_, engaged, kWaitSeconds));
  }
  /// Spins servo 1 once the port is open (the services come up before it).
  void spinServo1() {
    ASSERT_TRUE(waitFor([&] { return spinCall(1, 1).response.success; }, kWaitSeconds));
    ASSERT_TRUE(waitMoving(1, true));
  }

  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher e_stop_;
};

// First in the file: the simulator loses the first SPIN stop it is sent (--lose-servo-stops 1).
// The cable is out when the e-stop comes; after the replug the stop is the first frame on the bus;
// the line loses it, the servo still turns, and the node writes it again until the servo rests.
TEST_F(EStopBus, AStopEngagedWhileUnpluggedGoesFirstAfterTheReplugAndAgainWhenLost) {
  spinServo1();
  g_bus->reset();  // the cable is pulled
  ASSERT_TRUE(diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.value("connected") == "False"; }, [] { return ros::ok(); },
      kWaitSeconds));
  setEStop(true);
  const auto unconfirmed = diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.value("stops not yet confirmed").find("servo_1") == 0; },
      [] { return ros::ok(); }, kWaitSeconds);
  ASSERT_TRUE(unconfirmed.has_value());
  EXPECT_EQ(unconfirmed->level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_NE(unconfirmed->message.find("servo_1"), std::string::npos) << unconfirmed->message;
  EXPECT_TRUE(simServo(1)->moving) << "nothing can reach the servo while the cable is out";

  *g_bus = plugBus();  // the cable is back
  ASSERT_TRUE(
      (*g_bus)->waitForFrames([](const auto& frames) { return !frames.empty(); }, kWaitSeconds));
  EXPECT_EQ((*g_bus)->frames().front().bytes, kSpin1Stop) << "the stop is the first frame";
  ASSERT_TRUE(waitMoving(1, false)) << "the lost stop was never written again";
  EXPECT_EQ(servoBusStats(g_robot->stats()).stops_lost, 1u);
  EXPECT_GE(count((*g_bus)->frames(), kSpin1Stop), 2u);
  EXPECT_TRUE(diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.value("stops not yet confirmed") == "none"; },
      [] { return ros::ok(); }, kWaitSeconds));
}

// The user's report: a servo/read of an absent servo holds the bus for timeout * 4 = 2 s; a
// servo/spin waits behind it; the e-stop comes. The spin must never reach the wire.
TEST_F(EStopBus, AMotionWaitingBehindASlowTransactionIsRefusedWhenTheEStopComes) {
  const std::size_t spins_before = count((*g_bus)->frames(), kSpin1Continuous90);
  srd::ServoRead read;
  read.request.id = 7;  // nobody answers
  read.request.param = "voltage";
  std::thread reader([&] { ros::service::call("servo/read", read); });
  ASSERT_TRUE((*g_bus)->waitForFrames(
      [](const auto& frames) {
        return !frames.empty() && frames.back().bytes.size() > 4 && frames.back().bytes[4] == 7;
      },
      kWaitSeconds));
  srd::ServoSpin spin;
  std::thread mover([&] {
    spin.request.id = 1;
    spin.request.mode = 1;
    spin.request.speed_dps = 90;
    ros::service::call("servo/spin", spin);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the spin is waiting for the bus
  EXPECT_EQ(count((*g_bus)->frames(), kSpin1Continuous90), spins_before);
  setEStop(true);
  mover.join();
  reader.join();
  EXPECT_FALSE(spin.response.success);
  EXPECT_NE(spin.response.message.find("e_stop"), std::string::npos) << spin.response.message;
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // anything late would be out now
  EXPECT_EQ(count((*g_bus)->frames(), kSpin1Continuous90), spins_before)
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
  spinServo1();
  srd::ServoScan scan;
  scan.request.first_id = 10;
  scan.request.last_id = 25;  // absent: 16 x 0.5 s
  std::thread scanner([&] { ros::service::call("servo/scan", scan); });
  ASSERT_TRUE((*g_bus)->waitForFrames(
      [](const auto& frames) {
        return !frames.empty() && frames.back().bytes[2] == kPingCmd &&
               frames.back().bytes[4] >= 11;
      },
      kWaitSeconds));
  const std::size_t at_e_stop = (*g_bus)->frameCount();
  const auto engaged_at = std::chrono::steady_clock::now();
  setEStop(true);
  ASSERT_TRUE((*g_bus)->waitForFrames(
      [&](const auto& frames) { return count(frames, kSpin1Stop, at_e_stop) >= 1; }, kWaitSeconds));
  const std::vector<PtyTap::Frame> frames = (*g_bus)->frames();
  std::size_t pings_before_stop = 0;
  for (std::size_t i = at_e_stop; i < frames.size() && frames[i].bytes != kSpin1Stop; ++i) {
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
  g_bus_port = test_support::nodeParam(kNode, "servo_bus/port");
  const std::string base_port = test_support::nodeParam(kNode, "port");
  g_bus_sim_port = g_bus_port + "_sim";

  sim::SimOptions options;
  options.device("body").enabled = false;
  servoBusConfig(options).servo_ids = {0, 1, 2, 3};
  servoBusConfig(options).lost_stops = 1;
  options.device("servo_bus").link = g_bus_sim_port;
  options.device("base").link = base_port + "_sim";
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  srd::protocol::FramerConfig base_framer;
  base_framer.accept(serial_robot_driver::protocol::base::kFrames);
  PtyTap base(base_port, *options.device("base").link, base_framer);
  g_base = &base;
  std::unique_ptr<PtyTap> bus = plugBus();
  g_bus = &bus;

  const int result = RUN_ALL_TESTS();
  bus.reset();
  robot.stop();
  return result;
}
