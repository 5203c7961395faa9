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
#include <std_msgs/Bool.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
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
constexpr uint8_t kSpinCmd = 0x07;
constexpr uint8_t kReadAngleCmd = 0x0A;

// SPIN stops at speed 0: 12+4C+07+06+id.
const Bytes kSpin1Stop = {0x12, 0x4C, 0x07, 0x06, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x6C};
const Bytes kSpin2Stop = {0x12, 0x4C, 0x07, 0x06, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x6D};
const Bytes kSpin6Stop = {0x12, 0x4C, 0x07, 0x06, 0x06, 0x00, 0x00, 0x00, 0x00, 0x00, 0x71};
// Servo 1 counter-clockwise continuous at 90 deg/s: 12+4C+07+06+01+01+5A = 0xC7.
const Bytes kSpin1Continuous90 = {0x12, 0x4C, 0x07, 0x06, 0x01, 0x01, 0x5A, 0x00, 0x00, 0x00, 0xC7};

sim::RobotSim* g_robot = nullptr;
std::unique_ptr<PtyTap>* g_bus = nullptr;
std::string g_bus_port;
std::string g_bus_sim_port;

std::unique_ptr<PtyTap> plugBus() {
  srd::protocol::FramerConfig framer;
  framer.accept(srd::protocol::servo::kRequestFrames);
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

srd::ServoWrite writeCall(uint8_t id, const std::string& param, int64_t value) {
  srd::ServoWrite call;
  call.request.id = id;
  call.request.param = param;
  call.request.value = value;
  EXPECT_TRUE(ros::service::call("servo/write", call));
  return call;
}

std::size_t count(const std::vector<PtyTap::Frame>& frames, const Bytes& bytes,
                  std::size_t from = 0) {
  return static_cast<std::size_t>(
      std::count_if(frames.begin() + static_cast<long>(std::min(from, frames.size())), frames.end(),
                    [&](const PtyTap::Frame& f) { return f.bytes == bytes; }));
}

std::size_t countWhere(const std::vector<PtyTap::Frame>& frames, std::size_t from,
                       const std::function<bool(const Bytes&)>& match) {
  return static_cast<std::size_t>(
      std::count_if(frames.begin() + static_cast<long>(std::min(from, frames.size())), frames.end(),
                    [&](const PtyTap::Frame& f) { return f.bytes.size() > 5 && match(f.bytes); }));
}

class ServoEStop : public ::testing::Test {
 protected:
  ServoEStop() : diagnostics_(nh_, kNode) {
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
  void spinServo(uint8_t id) {
    ASSERT_TRUE(waitFor([&] { return spinCall(id, 1).response.success; }, kWaitSeconds));
    ASSERT_TRUE(waitMoving(id, true));
  }

  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher e_stop_;
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
  ASSERT_TRUE(
      waitFor([&] { return ros::service::call("servo/rotate", rotate) && rotate.response.success; },
              kWaitSeconds));
  ASSERT_TRUE(waitMoving(1, true));
  setEStop(true);
  ASSERT_TRUE(waitMoving(1, false)) << "the slow servo still turns under the e-stop";
  EXPECT_EQ(servoBusStats(g_robot->stats()).stops_lost, 1u);
  EXPECT_GE(count((*g_bus)->frames(), kSpin1Stop), 2u);
}

// The user's report: a servo/read of an absent servo holds the bus for 4 x 2 s; a servo/spin
// waits behind it; the e-stop is engaged and released a second later. The spin was accepted
// before the e-stop: it never reaches the wire, and its call says why.
TEST_F(ServoEStop, ASpinAcceptedBeforeAnEStopIsNotWrittenAfterItsRelease) {
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
  std::thread mover([&] { spin = spinCall(1, 1); });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the spin is waiting for the bus
  setEStop(true);
  std::this_thread::sleep_for(std::chrono::seconds(1));
  setEStop(false);
  mover.join();
  reader.join();
  EXPECT_FALSE(spin.response.success);
  EXPECT_NE(spin.response.message.find("e-stop engaged after this command was accepted"),
            std::string::npos)
      << spin.response.message;
  EXPECT_EQ(count((*g_bus)->frames(), kSpin1Continuous90), spins_before)
      << "a SPIN accepted before the e-stop was written after its release";
  EXPECT_FALSE(simServo(1)->moving);
}

// Engaged and released while the cable is out: the stop never went out, so the release keeps it
// and it is the first frame after the replug.
TEST_F(ServoEStop, AStopEngagedAndReleasedWhileUnpluggedGoesOutAfterTheReplug) {
  spinServo(1);
  g_bus->reset();  // the cable is pulled
  ASSERT_TRUE(diagnostics_.waitFor(
      "servo_bus", diagnostics_.latest("servo_bus").received,
      [](const auto& s) { return s.value("connected") == "False"; }, [] { return ros::ok(); },
      kWaitSeconds));
  setEStop(true);
  setEStop(false);
  *g_bus = plugBus();  // the cable is back
  ASSERT_TRUE(
      (*g_bus)->waitForFrames([](const auto& frames) { return !frames.empty(); }, kWaitSeconds));
  EXPECT_EQ((*g_bus)->frames().front().bytes, kSpin1Stop) << "the stop is the first frame";
  EXPECT_TRUE(waitMoving(1, false)) << "the release dropped the stop never written";
}

// Nothing answers a broadcast: refused, with a message, and nothing on the wire.
TEST_F(ServoEStop, ABroadcastSpinIsRefused) {
  const std::size_t before = (*g_bus)->frameCount();
  const srd::ServoSpin spin = spinCall(255, 1);
  EXPECT_FALSE(spin.response.success);
  EXPECT_NE(spin.response.message.find("broadcast"), std::string::npos) << spin.response.message;
  EXPECT_EQ(countWhere((*g_bus)->frames(), before,
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
  const std::size_t before = (*g_bus)->frameCount();
  setEStop(true);
  ASSERT_TRUE((*g_bus)->waitForFrames(
      [&](const auto& frames) { return count(frames, kSpin6Stop, before) >= 1; }, kWaitSeconds))
      << "the stop did not follow the servo to its new address";
  EXPECT_EQ(count((*g_bus)->frames(), kSpin2Stop, before), 0u);
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
  ASSERT_TRUE(ros::service::call("servo/relax", relax));
  EXPECT_TRUE(relax.response.success) << relax.response.message;
  ASSERT_TRUE(waitFor([&] { return simServo(1)->relaxed; }, kWaitSeconds));
  const std::size_t relaxed_at = (*g_bus)->frameCount();
  const auto polls_of_1 = [&](const std::vector<PtyTap::Frame>& frames) {
    return countWhere(frames, relaxed_at,
                      [](const Bytes& b) { return b[2] == kReadAngleCmd && b[4] == 1; });
  };
  ASSERT_TRUE((*g_bus)->waitForFrames([&](const auto& frames) { return polls_of_1(frames) >= 10; },
                                      kWaitSeconds));
  EXPECT_EQ(count((*g_bus)->frames(), kSpin1Stop, relaxed_at), 0u);
  EXPECT_TRUE(simServo(1)->relaxed);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_estop");
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
  base_framer.accept(srd::protocol::base::kFrames);
  PtyTap base(base_port, *options.device("base").link, base_framer);
  std::unique_ptr<PtyTap> bus = plugBus();
  g_bus = &bus;

  const int result = RUN_ALL_TESTS();
  bus.reset();
  robot.stop();
  return result;
}
