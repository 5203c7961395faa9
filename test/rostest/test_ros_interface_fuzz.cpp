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
#include <actionlib_msgs/GoalID.h>
#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Bool.h>
#include <std_srvs/Trigger.h>
#include <trajectory_msgs/JointTrajectory.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "serial_robot_driver/FollowJointTrajectoryActionGoal.h"
#include "serial_robot_driver/ServoDamping.h"
#include "serial_robot_driver/ServoHold.h"
#include "serial_robot_driver/ServoInfo.h"
#include "serial_robot_driver/ServoMove.h"
#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoRelax.h"
#include "serial_robot_driver/ServoResetUserData.h"
#include "serial_robot_driver/ServoRotate.h"
#include "serial_robot_driver/ServoScan.h"
#include "serial_robot_driver/ServoSpin.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/process_support.h"
#include "support/pty_tap.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::PtyTap;
using test_support::waitFor;

constexpr double kWaitSeconds = 30.0;
constexpr char kNode[] = "driver_node";
constexpr std::size_t kHugeArray = 100000;  // elements: bounded, not gigabytes
constexpr std::size_t kLongString = 10000;  // characters, only in short arrays

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

/// Extreme values of every kind a field can have, drawn from one seeded generator.
class Extremes {
 public:
  explicit Extremes(uint64_t seed) : rng_(seed) {}

  std::size_t pick(std::size_t n) {
    return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }

  double real() {
    const double kMax = std::numeric_limits<double>::max();
    const double kInf = std::numeric_limits<double>::infinity();
    const double values[] = {0.0,
                             -0.0,
                             1.0,
                             -1.0,
                             std::numeric_limits<double>::quiet_NaN(),
                             kInf,
                             -kInf,
                             1e308,
                             -1e308,
                             kMax,
                             -kMax,
                             std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::denorm_min(),
                             0.5,
                             3.2,
                             -3.2};
    if (chance(0.3)) return std::uniform_real_distribution<double>(-4.0, 4.0)(rng_);
    return values[pick(sizeof(values) / sizeof(values[0]))];
  }
  template <typename Int>
  Int integer() {
    using L = std::numeric_limits<Int>;
    const Int values[] = {0,
                          1,
                          2,
                          L::max(),
                          static_cast<Int>(L::max() - 1),
                          L::min(),
                          static_cast<Int>(L::min() + 1),
                          static_cast<Int>(255),
                          static_cast<Int>(254)};
    if (chance(0.3)) return static_cast<Int>(rng_());
    return values[pick(sizeof(values) / sizeof(values[0]))];
  }
  std::size_t size() {
    const std::size_t sizes[] = {0, 1, 2, 3, 7, 300, kHugeArray};
    return sizes[pick(sizeof(sizes) / sizeof(sizes[0]))];
  }
  /// A name: one of `known` (duplicates come from drawing twice), an unknown one, empty, long.
  std::string name(const std::vector<std::string>& known, bool short_only) {
    switch (pick(6)) {
      case 0:
        return "";
      case 1:
        return "no_such_joint";
      case 2:
        return short_only ? "servo_999" : std::string(kLongString, 'x');
      case 3:
        return "servo_" + std::to_string(integer<uint8_t>());
      default:
        return known[pick(known.size())];
    }
  }
  std::vector<std::string> names(std::size_t n, const std::vector<std::string>& known) {
    std::vector<std::string> out(n);
    for (std::string& each : out) each = name(known, n > 3);
    return out;
  }
  std::vector<double> reals(std::size_t n) {
    std::vector<double> out(n);
    for (double& each : out)
      each = chance(0.8) ? std::uniform_real_distribution<double>(-1, 1)(rng_) : real();
    return out;
  }
  /// A stamp: zero, now, just past, ahead within and beyond max_start_delay, the far future
  /// (4e9 s), the ends of uint32, an unnormalised nsec.
  ros::Time stamp() {
    const ros::Time now = ros::Time::now();
    ros::Time t;
    switch (pick(9)) {
      case 0:
        return ros::Time();
      case 1:
        return now;
      case 2:
        return now - ros::Duration(1.0);
      case 3:
        return now + ros::Duration(5.0);
      case 4:
        return now + ros::Duration(11.0);
      case 5:
        t.sec = 4000000000u;
        return t;
      case 6:
        t.sec = t.nsec = std::numeric_limits<uint32_t>::max();
        return t;
      case 7:
        t.nsec = 1;
        return t;
      default:
        t.sec = now.sec;
        t.nsec = std::numeric_limits<uint32_t>::max();
        return t;
    }
  }
  /// A duration: zero, negative, enormous, the ends of int32, unnormalised.
  ros::Duration duration() {
    ros::Duration d;
    switch (pick(6)) {
      case 0:
        return ros::Duration(0.0);
      case 1:
        d.sec = -1;
        return d;
      case 2:
        d.sec = std::numeric_limits<int32_t>::max();
        return d;
      case 3:
        d.sec = std::numeric_limits<int32_t>::min();
        return d;
      case 4:
        d.nsec = std::numeric_limits<int32_t>::max();
        return d;
      default:
        d.nsec = std::numeric_limits<int32_t>::min();
        return d;
    }
  }

 private:
  std::mt19937_64 rng_;
};

const std::vector<std::string> kJointNames = {"joint_1", "joint_2", "pan", "servo_1", "servo_2"};

/// A valid trajectory of a random subset of the joints, then 1..3 fields at their extremes.
trajectory_msgs::JointTrajectory fuzzTrajectory(Extremes& x) {
  trajectory_msgs::JointTrajectory msg;
  msg.header.stamp = x.chance(0.5) ? ros::Time() : x.stamp();
  msg.joint_names = x.chance(0.5) ? std::vector<std::string>{"joint_1", "joint_2"}
                                  : std::vector<std::string>{"pan", "joint_1"};
  const std::size_t points = x.chance(0.1) ? x.size() : 1 + x.pick(3);
  for (std::size_t p = 0; p < points; ++p) {
    trajectory_msgs::JointTrajectoryPoint point;
    point.positions = {0.1 * static_cast<double>(p % 5), -0.1};
    point.time_from_start = ros::Duration(0.2 * static_cast<double>(p + 1));
    msg.points.push_back(point);
  }
  const std::size_t mutations = 1 + x.pick(3);
  for (std::size_t m = 0; m < mutations; ++m) {
    trajectory_msgs::JointTrajectoryPoint* point =
        msg.points.empty() ? nullptr : &msg.points[x.pick(msg.points.size())];
    switch (x.pick(8)) {
      case 0:
        msg.header.stamp = x.stamp();
        break;
      case 1:
        msg.joint_names = x.names(x.chance(0.8) ? x.pick(4) : x.size(), kJointNames);
        break;
      case 2:
        if (point) point->time_from_start = x.duration();
        break;
      case 3:
        if (point) point->positions = x.reals(x.chance(0.7) ? 2 : x.size());
        break;
      case 4:
        if (point) point->velocities = x.reals(x.chance(0.7) ? 2 : x.size());
        break;
      case 5:
        if (point) point->accelerations = x.reals(x.chance(0.7) ? 2 : x.size());
        break;
      case 6:
        msg.points.clear();
        break;
      default:
        if (point && !point->positions.empty()) point->positions[0] = x.real();
        break;
    }
  }
  return msg;
}

sensor_msgs::JointState fuzzJointState(Extremes& x, const std::vector<std::string>& valid) {
  sensor_msgs::JointState msg;
  msg.header.stamp = x.stamp();
  msg.name = valid;
  msg.position = x.reals(valid.size());
  switch (x.pick(5)) {
    case 0:
      msg.name = x.names(x.chance(0.8) ? x.pick(5) : x.size(), kJointNames);
      break;
    case 1:
      msg.position = x.reals(x.chance(0.7) ? x.pick(5) : x.size());
      break;
    case 2:
      msg.velocity = x.reals(x.chance(0.7) ? valid.size() : x.size());
      break;
    case 3:
      msg.effort = x.reals(x.size());
      break;
    default:
      if (!msg.position.empty()) msg.position[0] = x.real();
      break;
  }
  return msg;
}

/// Publishers of every subscribed topic (e_stop is the fuzzer's own switch).
struct Topics {
  explicit Topics(ros::NodeHandle& nh)
      : cmd_vel(nh.advertise<geometry_msgs::Twist>("cmd_vel", 100)),
        joint_commands(nh.advertise<sensor_msgs::JointState>("joint_commands", 100)),
        servo_commands(nh.advertise<sensor_msgs::JointState>("servo_commands", 100)),
        joint_trajectory(nh.advertise<trajectory_msgs::JointTrajectory>("joint_trajectory", 100)),
        goal(nh.advertise<srd::FollowJointTrajectoryActionGoal>("follow_joint_trajectory/goal",
                                                                100)),
        cancel(nh.advertise<actionlib_msgs::GoalID>("follow_joint_trajectory/cancel", 100)) {}
  bool connected() const {
    for (const ros::Publisher* p :
         {&cmd_vel, &joint_commands, &servo_commands, &joint_trajectory, &goal, &cancel}) {
      if (p->getNumSubscribers() == 0) return false;
    }
    return true;
  }
  ros::Publisher cmd_vel, joint_commands, servo_commands, joint_trajectory, goal, cancel;
};

template <typename Service>
void call(const std::string& name, Service& service) {
  // The answer's content is the node's business; that it answers at all is what counts here.
  EXPECT_TRUE(ros::service::call(name, service)) << name << " gave no answer";
}

/// A servo id: mostly one that answers (0..3), else any, 255 (broadcast) included.
uint8_t servoId(Extremes& x) {
  return x.chance(0.5) ? static_cast<uint8_t>(x.pick(4)) : x.integer<uint8_t>();
}

std::vector<uint8_t> servoIds(Extremes& x) {
  std::vector<uint8_t> out(x.chance(0.8) ? x.pick(4) : x.size());
  for (uint8_t& each : out) each = servoId(x);
  return out;
}

/// A parameter name: known, dangerous, numeric, negative, enormous, empty or long.
std::string servoParam(Extremes& x) {
  const std::string params[] = {
      "",          "angle_limit_low", "servo_id",        "51",
      "-1",        "99999999999",     "response_switch", std::string(kLongString, 'p'),
      "mid_offset"};
  return params[x.pick(sizeof(params) / sizeof(params[0]))];
}

/// The servo services that read or write settings.
void fuzzSettingsService(Extremes& x) {
  switch (x.pick(8)) {
    case 0: {
      srd::ServoPing s;
      s.request.id = servoId(x);
      call("servo/ping", s);
      break;
    }
    case 1: {
      srd::ServoScan s;
      s.request.first_id = x.integer<uint8_t>();
      s.request.last_id = x.integer<uint8_t>();
      call("servo/scan", s);
      break;
    }
    case 2: {
      srd::ServoRead s;
      s.request.id = servoId(x);
      s.request.param = servoParam(x);
      call("servo/read", s);
      break;
    }
    case 3: {
      srd::ServoWrite s;
      s.request.id = servoId(x);
      s.request.param = servoParam(x);
      s.request.value = x.integer<int64_t>();
      call("servo/write", s);
      break;
    }
    case 4: {
      srd::ServoReadAll s;
      s.request.id = servoId(x);
      call("servo/read_all", s);
      break;
    }
    case 5: {
      srd::ServoResetUserData s;
      s.request.id = servoId(x);
      call("servo/reset_user_data", s);
      break;
    }
    case 6: {
      srd::ServoReadAngle s;
      s.request.id = servoId(x);
      s.request.multi_turn = x.chance(0.5);
      call("servo/read_angle", s);
      break;
    }
    default: {
      srd::ServoInfo s;
      s.request.id = servoId(x);
      call("servo/info", s);
      break;
    }
  }
}

void fuzzMove(Extremes& x) {
  srd::ServoMove s;
  s.request.id = servoId(x);
  s.request.angle_deg = x.real();
  s.request.multi_turn = x.chance(0.5);
  s.request.interval_ms = x.integer<uint32_t>();
  s.request.velocity_dps = x.real();
  s.request.accel_ms = x.integer<uint16_t>();
  s.request.decel_ms = x.integer<uint16_t>();
  s.request.power_mw = x.integer<uint16_t>();
  call("servo/move", s);
}

/// The servo services that move or hold (`wait` false, see the top of the file).
void fuzzMotionService(Extremes& x) {
  switch (x.pick(6)) {
    case 0: {
      srd::ServoRotate s;
      s.request.id = servoId(x);
      s.request.angle_deg = x.real();
      s.request.interval_ms = x.integer<uint16_t>();
      s.request.power_mw = x.integer<uint16_t>();
      call("servo/rotate", s);
      break;
    }
    case 1:
      fuzzMove(x);
      break;
    case 2: {
      srd::ServoSpin s;
      s.request.id = servoId(x);
      s.request.clockwise = x.chance(0.5);
      s.request.mode = x.integer<uint8_t>();
      s.request.speed_dps = x.integer<uint16_t>();
      s.request.value = x.integer<uint16_t>();
      call("servo/spin", s);
      break;
    }
    case 3: {
      srd::ServoDamping s;
      s.request.id = servoId(x);
      s.request.power_mw = x.integer<uint16_t>();
      call("servo/damping", s);
      break;
    }
    case 4: {
      srd::ServoRelax s;
      s.request.ids = servoIds(x);
      call("servo/relax", s);
      break;
    }
    default: {
      srd::ServoHold s;
      s.request.ids = servoIds(x);
      call("servo/hold", s);
      break;
    }
  }
}

/// One service request with its fields at extremes (the Trigger services have none).
void fuzzService(Extremes& x) {
  const char* triggers[] = {"imu/calibrate", "base/reset", "base/reset_odometry",
                            "base/clear_encoders"};
  switch (x.pick(4)) {
    case 0:
      fuzzSettingsService(x);
      break;
    case 1:
      fuzzMotionService(x);
      break;
    case 2:
      fuzzMotionService(x);
      break;
    default: {
      std_srvs::Trigger s;
      call(triggers[x.pick(4)], s);
      break;
    }
  }
}

/// One input to a random topic or service; returns what it was sent to.
void fuzzOne(Extremes& x, Topics& topics) {
  switch (x.pick(8)) {
    case 0: {
      geometry_msgs::Twist twist;
      twist.linear.x = x.real();
      twist.angular.z = x.real();
      twist.linear.y = x.real();
      topics.cmd_vel.publish(twist);
      break;
    }
    case 1:
      topics.joint_commands.publish(fuzzJointState(x, {"joint_1", "joint_2"}));
      break;
    case 2:
      topics.servo_commands.publish(fuzzJointState(x, {"servo_1", "servo_3"}));
      break;
    case 3:
      topics.joint_trajectory.publish(fuzzTrajectory(x));
      break;
    case 4: {
      srd::FollowJointTrajectoryActionGoal goal;
      goal.header.stamp = x.stamp();
      goal.goal_id.stamp = x.stamp();
      goal.goal_id.id =
          x.chance(0.2) ? std::string(kLongString, 'g') : "fuzz_" + std::to_string(x.pick(5));
      goal.goal.trajectory = fuzzTrajectory(x);
      goal.goal.goal_time_tolerance = x.duration();
      srd::JointTolerance tolerance;
      tolerance.name = x.name(kJointNames, true);
      tolerance.position = x.real();
      tolerance.velocity = x.real();
      goal.goal.path_tolerance.assign(x.chance(0.8) ? x.pick(3) : x.size(), tolerance);
      goal.goal.goal_tolerance.assign(x.pick(3), tolerance);
      topics.goal.publish(goal);
      break;
    }
    case 5: {
      actionlib_msgs::GoalID cancel;
      cancel.id = x.chance(0.5) ? "" : "fuzz_" + std::to_string(x.pick(5));
      cancel.stamp = x.stamp();
      topics.cancel.publish(cancel);
      break;
    }
    default:
      fuzzService(x);
      break;
  }
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
    ASSERT_TRUE(
        waitFor([&] { return ros::service::call("servo/spin", spin) && spin.response.success; },
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
    EXPECT_TRUE(
        waitFor([&] { return ros::service::call("servo/ping", ping) && ping.response.online; },
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
    if (count_ >= 30) EXPECT_GT(status->number("inputs refused"), 0u) << "nothing refused?";
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
  sim::servoBusConfig(options).servo_ids = {1, 2};
  options.device("base").link = base_port + "_sim";
  options.device("body").link = body_port + "_sim";
  options.device("servo_bus").link = bus_port + "_sim";
  sim::RobotSim robot(options);
  robot.start();
  g_robot = &robot;
  srd::protocol::FramerConfig base_framer, body_framer, bus_framer;
  base_framer.accept(srd::protocol::base::kFrames);
  body_framer.accept(srd::protocol::body::kSyncWriteFrames);
  bus_framer.accept(srd::protocol::servo::kRequestFrames);
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
