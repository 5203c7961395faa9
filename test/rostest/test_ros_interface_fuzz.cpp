// The ROS interface fuzzer (ros_interface_fuzz.test): seeded inputs on every subscribed topic and
// every service of driver_node, each starting from a valid message or request and taking one to
// three of its fields to their extremes (the type's largest and smallest, 0, NaN, +-Inf, +-1e308,
// empty and huge arrays, mismatched lengths, duplicate and unknown names, zero, far-future, past
// and unnormalised stamps, negative and enormous durations, long strings), with bus servo 1
// spinning and a part of the run under the e-stop. Afterwards the node must be the same live
// process, answer servo/ping, publish joint_states, report no callback error, and none of the taps
// may have seen a motion frame while the e-stop held.
//
// SRD_FUZZ_SEED (default: from the clock, printed) and SRD_FUZZ_COUNT (default 1500 inputs, the CI
// run) choose the run; scripts/fuzz_ros_interface.sh runs a long one. `wait` of the motion
// services stays false: a waiting call holds a service thread for up to 65 s by design.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/process_support.h"
#include "support/pty_tap.h"
#include "support/ros_fuzz_inputs.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using ros_fuzz::Extremes;
using ros_fuzz::fuzzOne;
using ros_fuzz::Topics;
using test_support::PtyTap;
using test_support::waitFor;

constexpr double kWaitSeconds = 30.0;
constexpr char kNode[] = "driver_node";

sim::RobotSim* g_robot = nullptr;
PtyTap* g_base = nullptr;
PtyTap* g_body = nullptr;
PtyTap* g_bus = nullptr;

// Motion frames, from docs/protocols.md. Base: a wheel-speed frame (MSGID 01) with a speed other
// than 0 (55 AA LEN SEQ 01 L_hi L_lo R_hi R_lo ...). Body: every sync-write. Bus: ROTATE (8), the
// newer moves (11..15) and a SPIN (7) whose method's bits 1..0 are not 0 (stop); DAMPING (9) is
// torque-off and moves nothing actively, so it is not counted.
bool baseMotion(const PtyTap::Frame& f) {
  return f.bytes.size() >= 9 && f.bytes[4] == 0x01 &&
         (f.bytes[5] || f.bytes[6] || f.bytes[7] || f.bytes[8]);
}
bool busMotion(const PtyTap::Frame& f) {
  if (f.bytes.size() < 6) return false;
  const uint8_t cmd = f.bytes[2];
  if (cmd == 7) return (f.bytes[5] & 0x03) != 0;
  return cmd == 8 || (cmd >= 11 && cmd <= 15);
}

/// Motion frames a tap saw arriving between `from` and `to`.
std::size_t motionFramesBetween(const PtyTap& tap,
                                const std::function<bool(const PtyTap::Frame&)>& motion,
                                PtyTap::Clock::time_point from, PtyTap::Clock::time_point to) {
  std::size_t count = 0;
  for (const PtyTap::Frame& f : tap.frames()) {
    if (f.arrival >= from && f.arrival <= to && motion(f)) ++count;
  }
  return count;
}

uint64_t envNumber(const char* name, uint64_t fallback) {
  const char* text = std::getenv(name);
  return text && *text ? std::strtoull(text, nullptr, 10) : fallback;
}

/// The node, its topics and its e-stop as the fuzzer sees them; the run's seed and size.
class RosInterfaceFuzz : public ::testing::Test {
 protected:
  RosInterfaceFuzz()
      : diagnostics_(nh_, kNode),
        e_stop_(nh_.advertise<std_msgs::Bool>("e_stop", 1, /*latch=*/true)),
        topics_(nh_),
        joint_states_(nh_, "joint_states", 1),
        seed_(envNumber(
            "SRD_FUZZ_SEED",
            static_cast<uint64_t>(std::chrono::system_clock::now().time_since_epoch().count()))),
        count_(envNumber("SRD_FUZZ_COUNT", 1500)) {}

  void SetUp() override {
    ASSERT_TRUE(waitFor([&] { return topics_.connected() && e_stop_.getNumSubscribers() > 0; },
                        kWaitSeconds));
    ASSERT_TRUE(ros::service::waitForService("servo/spin", 30000));
    setEStop(false);
    ASSERT_TRUE(
        waitFor([&] { return (pid_ = test_support::nodePid("/driver_node")) > 0; }, kWaitSeconds));
    std::printf(
        "ros_interface_fuzz: seed %llu, %llu inputs (SRD_FUZZ_SEED=%llu SRD_FUZZ_COUNT=%llu "
        "to repeat)\n",
        static_cast<unsigned long long>(seed_), static_cast<unsigned long long>(count_),
        static_cast<unsigned long long>(seed_), static_cast<unsigned long long>(count_));
    RecordProperty("seed", std::to_string(seed_));
  }

  void setEStop(bool engaged) {
    ASSERT_TRUE(test_support::setEStopAndWait(e_stop_, diagnostics_, engaged, kWaitSeconds));
  }

  void spinServo1(uint8_t mode) {
    srd::ServoSpin spin;
    spin.request.id = 1;
    spin.request.mode = mode;
    spin.request.speed_dps = 90;
    ASSERT_TRUE(waitFor(
        [&] { return test_support::callService("servo/spin", spin) && spin.response.success; },
        kWaitSeconds));
  }

  /// Sends the run's inputs, a third before, a third under and a third after the e-stop; sets
  /// when the e-stop was known to hold. Stops at the first input after which the node is gone.
  void sendInputs() {
    Extremes x(seed_);
    const uint64_t engage_at = count_ / 3, release_at = count_ - count_ / 3;
    ros::Rate pace(200);  // topic messages at most 200/s: their queues hold 10
    held_from_ = held_until_ = PtyTap::Clock::now();
    for (uint64_t i = 0; i < count_ && ros::ok(); ++i) {
      if (i == engage_at) {
        setEStop(true);
        held_from_ = PtyTap::Clock::now();
      }
      if (i == release_at) {
        held_until_ = PtyTap::Clock::now();
        setEStop(false);
      }
      fuzzOne(x, topics_);
      pace.sleep();
      ASSERT_TRUE(test_support::processAlive(pid_))
          << "driver_node died at input " << i << " (seed " << seed_ << ")";
    }
  }

  /// The same process, still answering and publishing.
  void expectStillServing() {
    ASSERT_TRUE(test_support::processAlive(pid_)) << "seed " << seed_;
    EXPECT_EQ(test_support::nodePid("/driver_node"), pid_) << "driver_node was restarted";
    srd::ServoPing ping;
    ping.request.id = 1;
    EXPECT_TRUE(waitFor(
        [&] { return test_support::callService("servo/ping", ping) && ping.response.online; },
        kWaitSeconds));
    const uint64_t states = joint_states_.count();
    EXPECT_TRUE(joint_states_.waitForCount(states + 50, kWaitSeconds)) << "joint_states stopped";
  }

  void expectNoMotionUnderTheEStop() const {
    const auto any = [](const PtyTap::Frame&) { return true; };
    EXPECT_EQ(motionFramesBetween(*g_base, baseMotion, held_from_, held_until_), 0u)
        << "seed " << seed_;
    EXPECT_EQ(motionFramesBetween(*g_body, any, held_from_, held_until_), 0u) << "seed " << seed_;
    EXPECT_EQ(motionFramesBetween(*g_bus, busMotion, held_from_, held_until_), 0u)
        << "seed " << seed_;
  }

  /// The node's own count: inputs refused (some, in any run of size), no callback error.
  void expectRefusalsAndNoCallbackError() {
    const auto status = diagnostics_.waitFor(
        "e_stop", diagnostics_.latest("e_stop").received, [](const auto&) { return true; },
        [] { return ros::ok(); }, kWaitSeconds);
    ASSERT_TRUE(status.has_value());
    EXPECT_EQ(status->number("callback errors"), 0u)
        << "an input reached an unexpected error (seed " << seed_ << ")";
    std::printf("ros_interface_fuzz: %llu inputs; inputs refused %s, callback errors %s\n",
                static_cast<unsigned long long>(count_), status->value("inputs refused").c_str(),
                status->value("callback errors").c_str());
    if (count_ >= 30) {
      EXPECT_GT(status->number("inputs refused"), 0u) << "nothing refused?";
    }
  }

  ros::NodeHandle nh_;
  test_support::DiagnosticsWatch diagnostics_;
  ros::Publisher e_stop_;
  Topics topics_;
  test_support::TopicCounter<sensor_msgs::JointState> joint_states_;
  const uint64_t seed_;
  const uint64_t count_;
  int pid_ = -1;
  PtyTap::Clock::time_point held_from_, held_until_;
};

TEST_F(RosInterfaceFuzz, NoInputEndsTheNodeOrMovesAnythingUnderTheEStop) {
  spinServo1(1);  // spinning, as in the field when the bad message came
  sendInputs();
  expectStillServing();
  expectNoMotionUnderTheEStop();
  expectRefusalsAndNoCallbackError();
  spinServo1(0);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_ros_interface_fuzz");
  const std::string base_port = test_support::nodeParam(kNode, "port");
  const std::string body_port = test_support::nodeParam(kNode, "body/port");
  const std::string bus_port = test_support::nodeParam(kNode, "servo_bus/port");

  sim::SimOptions options;
  srd::devices::servo_bus::sim::servoBusConfig(options).servo_ids = {1, 2};
  options.device("base").link = base_port + "_sim";
  options.device("body").link = body_port + "_sim";
  options.device("servo_bus").link = bus_port + "_sim";
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  srd::protocol::FramerConfig base_framer, body_framer, bus_framer;
  base_framer.accept(srd::devices::base::kFrames);
  body_framer.accept(srd::devices::body::kSyncWriteFrames);
  bus_framer.accept(srd::devices::servo_bus::kRequestFrames);
  PtyTap base(base_port, *options.device("base").link, base_framer);
  PtyTap body(body_port, *options.device("body").link, body_framer);
  PtyTap bus(bus_port, *options.device("servo_bus").link, bus_framer);
  g_base = &base;
  g_body = &body;
  g_bus = &bus;

  const int result = RUN_ALL_TESTS();
  robot.stop();
  return result;
}
