// What the rostests of the bus servos share: frames written out by hand from docs/protocols.md,
// section 3, and service-call helpers; then two rigs:
//  - servo_bus_node.test: the bus servos this test plays on the nodes' ptys (/driver_node:
//    dangerous writes refused, echoing adapter; /armed/driver_node: allowed). "Nothing was
//    written" is checked without timing: after a rejected call the test pings servo 3 and requires
//    that the bytes the pty received in between are exactly that PING.
//  - estop_bus.test, servo_estop.test, bus_yield.test: robot_sim (in the test's process) plays the
//    bus servos behind a tap that records every frame the node writes (the tap is the cable: it is
//    pulled and plugged again), and the base behind a tap of its own when the test hosts it.
#pragma once

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/Bool.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/fake_device.h"
#include "support/golden_frames.h"
#include "support/pty_tap.h"
#include "support/ros_test_support.h"

namespace servo_bus_node_test {

namespace srd = serial_robot_driver;
namespace protocol = serial_robot_driver::protocol;
namespace sim = serial_robot_driver::sim;
using test_support::Bytes;
using test_support::Clock;
using test_support::concat;
using test_support::PtyTap;
using test_support::secondsSince;
using test_support::waitFor;

using namespace golden::servo;  // NOLINT: the frames shared with the unit tests

// --- more frames written out by hand from docs/protocols.md, section 3 (SUM = byte sum mod 256) --
inline const Bytes kPing4 = {0x12, 0x4C, 0x01, 0x01, 0x04, 0x64};
// over_temperature (41 = 0x29) of servo 3 := 80, answered with result 0.
inline const Bytes kWriteOverTemp3 = {0x12, 0x4C, 0x04, 0x04, 0x03, 0x29, 0x50, 0x00, 0xE2};
inline const Bytes kWriteOverTemp3Failed = {0x05, 0x1C, 0x04, 0x03, 0x03, 0x29, 0x00, 0x54};
inline const Bytes kPing2 = {0x12, 0x4C, 0x01, 0x01, 0x02, 0x62};
// RESET_USER_DATA id 6: 5E + 02 + 01 + 06 = 67 (the armed bus leaves it unanswered).
inline const Bytes kResetUserData6 = {0x12, 0x4C, 0x02, 0x01, 0x06, 0x67};

// --- the servos on a pty ----------------------------------------------------------------------

/// The bus servos on a pty (a scripted FakeDevice that records every byte the node writes).
using ServoBusPlayer = test_support::FakeDevice;

/// Plays the bus servos at `path`: answers the requests it is scripted for; with `echo`, every
/// request is written back first, as an adapter with a looped-back transmit line does.
inline std::unique_ptr<ServoBusPlayer> servoBus(const std::string& path, bool echo) {
  protocol::FramerConfig config;
  config.accept(serial_robot_driver::devices::servo_bus::kRequestFrames);
  auto bus = std::make_unique<ServoBusPlayer>(path, config, echo);
  bus->plug();
  return bus;
}

inline ServoBusPlayer* g_safe = nullptr;  // /driver_node: dangerous writes refused, echoing adapter
inline ServoBusPlayer* g_armed = nullptr;  // /armed/driver_node: dangerous writes allowed

inline std::string safeService(const std::string& name) { return "servo/" + name; }
inline std::string armedService(const std::string& name) { return "armed/servo/" + name; }

/// Calls `service` and returns its answer; a call roscpp lost is tried again (callService), and
/// a node that never answers fails the test.
template <typename Srv>
Srv call(const std::string& service, Srv srv) {
  if (!test_support::callService(service, srv)) ADD_FAILURE() << service << ": no answer";
  return srv;
}

/// servo/spin of servo `id`: mode 0 stops it, any other mode turns it at 90 deg/s.
inline srd::ServoSpin spinCall(uint8_t id, uint8_t mode) {
  srd::ServoSpin srv;
  srv.request.id = id;
  srv.request.mode = mode;
  srv.request.speed_dps = mode == 0 ? 0 : 90;
  return call("servo/spin", srv);
}

inline srd::ServoPing ping(const std::string& service, uint8_t id) {
  srd::ServoPing srv;
  srv.request.id = id;
  return call(service, srv);
}

/// Pings servo 3 (which answers) and returns what the pty received since `mark` before that PING:
/// everything the node wrote in between. The trailing PING frames are checked and cut off (more
/// than one only if a busy machine made the node re-send).
inline Bytes bytesBeforeNextPing(ServoBusPlayer& bus, const std::string& ping_service,
                                 std::size_t mark) {
  const srd::ServoPing srv = ping(ping_service, 3);
  EXPECT_TRUE(srv.response.online) << srv.response.message;
  Bytes bytes = bus.bytesSince(mark);
  std::size_t pings = 0;
  while (bytes.size() >= kPing3.size() &&
         std::equal(kPing3.begin(), kPing3.end(), bytes.end() - kPing3.size())) {
    bytes.resize(bytes.size() - kPing3.size());
    ++pings;
  }
  EXPECT_GE(pings, 1u) << "the PING of servo 3 did not reach the pty last";
  return bytes;
}

inline srd::ServoMove moveRequest(uint8_t id, double angle_deg, bool multi_turn,
                                  uint32_t interval_ms, double velocity_dps, uint16_t accel_ms,
                                  uint16_t decel_ms) {
  srd::ServoMove srv;
  srv.request.id = id;
  srv.request.angle_deg = angle_deg;
  srv.request.multi_turn = multi_turn;
  srv.request.interval_ms = interval_ms;
  srv.request.velocity_dps = velocity_dps;
  srv.request.accel_ms = accel_ms;
  srv.request.decel_ms = decel_ms;
  return srv;
}

inline std::pair<bool, std::string> readParam(const std::string& prefix, uint8_t id,
                                              const char* param) {
  srd::ServoRead srv;
  srv.request.id = id;
  srv.request.param = param;
  srv = call(prefix + "read", srv);
  return {srv.response.success, srv.response.message};
}

inline std::pair<bool, std::string> writeParam(const std::string& prefix, uint8_t id,
                                               const char* param, int64_t value) {
  srd::ServoWrite srv;
  srv.request.id = id;
  srv.request.param = param;
  srv.request.value = value;
  srv = call(prefix + "write", srv);
  return {srv.response.success, srv.response.message};
}

// --- robot_sim's bus servos behind a tap (estop_bus, servo_estop, bus_yield) ------------------

inline sim::RobotSim* g_robot = nullptr;  // the simulated robot while the tests run
inline std::unique_ptr<PtyTap> g_bus;     // the bus's tap (the cable): reset() pulls it
inline std::string g_bus_port;            // what the node opens for the bus
inline std::string g_bus_sim_port;        // the simulator's side of it

/// A tap between the node's bus port and the simulator's: the cable plugged (again).
inline std::unique_ptr<PtyTap> plugBus() {
  protocol::FramerConfig framer;
  framer.accept(serial_robot_driver::devices::servo_bus::kRequestFrames);
  return std::make_unique<PtyTap>(g_bus_port, g_bus_sim_port, framer);
}

/// The simulated servo at `id` now; none when no servo has that address.
inline std::optional<serial_robot_driver::devices::servo_bus::sim::BusServoSnapshot> simServo(
    uint8_t id) {
  for (const serial_robot_driver::devices::servo_bus::sim::BusServoSnapshot& servo :
       serial_robot_driver::devices::servo_bus::sim::servoBusStats(g_robot->stats()).servos) {
    if (servo.id == id) return servo;
  }
  return std::nullopt;
}

/// How many of `frames`, from the index `from` on, are `bytes`.
inline std::size_t count(const std::vector<PtyTap::Frame>& frames, const Bytes& bytes,
                         std::size_t from = 0) {
  return static_cast<std::size_t>(
      std::count_if(frames.begin() + static_cast<long>(std::min(from, frames.size())), frames.end(),
                    [&](const PtyTap::Frame& f) { return f.bytes == bytes; }));
}

/// The options of a robot_sim that plays the bus servos `ids` for the node's bus port `bus_port`
/// (its side at `<bus_port>_sim`), without the body; sets g_bus_port and g_bus_sim_port.
inline sim::SimOptions simBusOptions(const std::string& bus_port, std::vector<uint8_t> ids) {
  g_bus_port = bus_port;
  g_bus_sim_port = bus_port + "_sim";
  sim::SimOptions options;
  options.device("body").enabled = false;
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).servo_ids = std::move(ids);
  options.device("servo_bus").link = g_bus_sim_port;
  return options;
}

/// The robot_sim of the e-stop tests: bus servos 0..3 for the node's servo_bus/port, the first
/// SPIN stop lost on the line.
inline sim::SimOptions firstStopLostOptions(const std::string& node) {
  sim::SimOptions options =
      simBusOptions(test_support::nodeParam(node, "servo_bus/port"), {0, 1, 2, 3});
  serial_robot_driver::devices::servo_bus::sim::servoBusConfig(options).lost_stops = 1;
  return options;
}

/// RUN_ALL_TESTS() with the robot_sim of `options` running (g_robot) and the bus plugged (g_bus).
/// A hosted base is played for the node's `base_port` behind a tap of its own, `*base_tap` while
/// the tests run. Returns RUN_ALL_TESTS()'s result.
inline int runAllTestsOnSimBus(sim::SimOptions options, const std::string& base_port = "",
                               PtyTap** base_tap = nullptr) {
  const bool base_hosted = options.hosts("base");
  if (base_hosted) options.device("base").link = base_port + "_sim";
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  std::unique_ptr<PtyTap> base;
  if (base_hosted) {
    protocol::FramerConfig base_framer;
    base_framer.accept(serial_robot_driver::devices::base::kFrames);
    base = std::make_unique<PtyTap>(base_port, *options.device("base").link, base_framer);
    if (base_tap != nullptr) *base_tap = base.get();
  }
  g_bus = plugBus();

  const int result = RUN_ALL_TESTS();
  g_bus.reset();
  robot.stop();
  g_robot = nullptr;
  return result;
}

/// A test of the node `node` on the simulated bus: a latched e_stop publisher, the node's
/// /diagnostics and waits of up to `wait_s`. SetUp() waits for the node and releases the e-stop;
/// each test ends with the e-stop released and servo 1 stopped.
class SimBusTest : public ::testing::Test {
 protected:
  SimBusTest(const std::string& node, double wait_s) : diagnostics_(nh_, node), wait_s_(wait_s) {
    e_stop_ = nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true);
  }
  ~SimBusTest() override {
    if (reader_.joinable()) reader_.join();
  }
  void SetUp() override {
    ASSERT_NO_FATAL_FAILURE(waitForTheNode());
    setEStop(false);
  }
  void TearDown() override {
    setEStop(false);
    spinCall(1, 0);
  }
  /// Waits for the node's e_stop subscription and its services.
  void waitForTheNode() {
    ASSERT_TRUE(waitFor([&] { return e_stop_.getNumSubscribers() > 0; }, wait_s_));
    ASSERT_TRUE(ros::service::waitForService("servo/spin", 30000));
  }
  void setEStop(bool engaged) {
    ASSERT_TRUE(test_support::setEStopAndWait(e_stop_, diagnostics_, engaged, wait_s_));
  }
  bool waitMoving(uint8_t id, bool moving) const {
    return waitFor([&] { return simServo(id) && simServo(id)->moving == moving; }, wait_s_);
  }
  /// Spins servo `id` once the port is open (the services come up before it).
  void spinServo(uint8_t id) {
    ASSERT_TRUE(waitFor([&] { return spinCall(id, 1).response.success; }, wait_s_));
    ASSERT_TRUE(waitMoving(id, true));
  }
  /// Starts a servo/read of the absent servo 7 on reader_: it holds the bus for all its attempts.
  /// True once its first frame is on the wire.
  bool holdTheBusWithAReadOfServo7() {
    reader_ = std::thread([] {
      srd::ServoRead read;
      read.request.id = 7;  // nobody answers
      read.request.param = "voltage";
      test_support::callService("servo/read", read);
    });
    return g_bus->waitForFrames(
        [](const auto& frames) {
          return !frames.empty() && frames.back().bytes.size() > 4 && frames.back().bytes[4] == 7;
        },
        wait_s_);
  }
  /// Pulls the bus's cable (its tap); true once the node reports the bus disconnected.
  bool pullTheCable() {
    g_bus.reset();
    return diagnostics_
        .waitFor(
            "servo_bus", diagnostics_.latest("servo_bus").received,
            [](const auto& s) { return s.value("connected") == "False"; }, [] { return ros::ok(); },
            wait_s_)
        .has_value();
  }
  /// Plugs the bus's cable back; true once the node wrote a frame on it.
  bool plugTheCableBack() {
    g_bus = plugBus();
    return g_bus->waitForFrames([](const auto& frames) { return !frames.empty(); }, wait_s_);
  }

  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher e_stop_;
  const double wait_s_;
  std::thread reader_;  // the read of holdTheBusWithAReadOfServo7()
};

}  // namespace servo_bus_node_test
