// Stress of the servo-bus services on the port shared with the wheeled base and the body board.
//
// servo_stress.test launches /servo_stress/driver_node with all three devices on one port: servo
// transactions share the port's reader thread and its writes with the 50 Hz wheel heartbeat and
// 100 Hz telemetry. This test plays the robot with the simulator library (sim::RobotSim) in its own
// process, bus servos 0, 1, 2 online, 5 listed but silent and 9 absent, and while it publishes
// cmd_vel (20 Hz) and joint_commands (10 Hz) it makes 310 service calls from three threads:
//   two threads ping, read, write, read_angle and read_all the online servos: every call must
//     succeed, and read_all must return what this thread last wrote (answers reach the right call);
//   one thread pings and reads the silent ids: every call must fail saying the servo "did not
//     answer", and return within timeout * (retries + 1) + kOfflineMargin.
// Every call must return (the calls run on threads the test waits for with a deadline).
//
// Everything else is checked by COUNTING at the simulator, never by timing:
//  - the wheel heartbeat never lapsed: the simulated base sent no FF error frame and saw no
//    timeout, and received exactly one Reset (the one after the port opened; the node sends
//    another only when its own sending gap reached the 1 s heartbeat), no frame out of sequence;
//    the speed frames it received over the window are >= 90 % of window * 50 Hz (a loose bound:
//    the two checks before are the real ones). The node's "loop overruns" is printed, not checked.
//  - telemetry kept flowing, nothing lost: the window opens with a snapshot (joint_states received
//    first, then the simulator's intact telemetry count) and closes by stopping the simulator and
//    waiting until everything in flight has arrived, so the closing edge is exact and the opening
//    edge can only add the frames still in flight at the snapshot:
//      0 <= joint_states received in the window - frames sent in the window <= kOpeningInFlight.
//    Over the whole run it is exact: frames lost = sent - received, and only the bytes the node
//    never read (flushed when it opened the port) can hide them: 32 * lost <= bytes unread.
//  - every joint command reached the simulated board as one sync-write, none arrived broken, and
//    the simulator never had to discard a frame because the node did not read its port.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <geometry_msgs/Twist.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

#include "serial_robot_driver/ServoPing.h"
#include "serial_robot_driver/ServoRead.h"
#include "serial_robot_driver/ServoReadAll.h"
#include "serial_robot_driver/ServoReadAngle.h"
#include "serial_robot_driver/ServoWrite.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/ros_test_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
namespace srd = serial_robot_driver;
using test_support::Clock;
using test_support::DiagnosticsWatch;
using test_support::TopicCounter;
using test_support::waitFor;

const std::vector<uint8_t> kOnlineIds = {0, 1, 2};
constexpr uint8_t kSilentId = 5;  // on the bus, never answers
constexpr uint8_t kAbsentId = 9;  // not on the bus at all
constexpr int kOnlineCallsPerThread = 125;
constexpr int kOfflineCalls = 60;
constexpr double kTelemetryRateHz = 100.0;
constexpr double kBaseLoopRateHz = 50.0;  // the node's default loop_rate
// Added to timeout * (retries + 1) for an offline call: the call may queue behind an online
// transaction, and a loaded machine delays the service round trip. Generous on purpose: the
// bound catches calls that wait far longer than the bus timeout (a hang, a global queue), not
// milliseconds.
constexpr double kOfflineMargin = 1.0;
// Every call thread must have finished by then (~7 s expected); after it a call counts as hung.
constexpr double kCallDeadline = 30.0;
// Telemetry frames the node may still have had in flight (read but not yet received here) at the
// snapshot opening the window: 200 ms at 100 Hz, far more than a local round trip takes.
constexpr int64_t kOpeningInFlight = 20;
constexpr std::size_t kTelemetryFrameBytes = 32;  // 24 + 4 * 2 servos, no foot block

uint64_t telemetryIntact(const sim::SimStats& s) {
  return s.sent[static_cast<std::size_t>(sim::OutputKind::kTelemetry)].intact;
}
uint64_t speedFramesReceived(const sim::SimStats& s) {
  return s.base.speed_frames_applied + s.base.speed_frames_ignored;
}

/// Publishes cmd_vel at 20 Hz and joint_commands at 10 Hz (absolute deadlines) until stopped.
class Motion {
 public:
  explicit Motion(ros::NodeHandle& nh)
      : cmd_vel_(nh.advertise<geometry_msgs::Twist>("cmd_vel", 10)),
        joint_commands_(nh.advertise<sensor_msgs::JointState>("joint_commands", 10)) {}
  ~Motion() { stop(); }

  bool waitConnected() {
    return waitFor([&] { return cmd_vel_.getNumSubscribers() > 0; }, 20) &&
           waitFor([&] { return joint_commands_.getNumSubscribers() > 0; }, 20);
  }
  void start() {
    thread_ = std::thread([this] {
      const Clock::time_point start = Clock::now();
      Clock::time_point next = start;
      for (uint64_t tick = 0; !stop_; ++tick) {
        const double t = test_support::secondsSince(start);
        geometry_msgs::Twist twist;
        twist.linear.x = 0.3 * std::sin(t);
        twist.angular.z = 0.6 * std::cos(0.7 * t);
        cmd_vel_.publish(twist);
        ++cmd_vel_sent_;
        if (tick % 2 == 0) {
          sensor_msgs::JointState command;
          command.name = {"joint_1", "joint_2"};
          command.position = {0.5 * std::sin(0.5 * t), -0.5 * std::sin(0.5 * t)};
          joint_commands_.publish(command);
          ++joint_commands_sent_;
        }
        next += std::chrono::milliseconds(50);
        std::this_thread::sleep_until(next);
      }
    });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  uint64_t cmdVelSent() const { return cmd_vel_sent_; }
  uint64_t jointCommandsSent() const { return joint_commands_sent_; }

 private:
  ros::Publisher cmd_vel_;
  ros::Publisher joint_commands_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> cmd_vel_sent_{0};
  std::atomic<uint64_t> joint_commands_sent_{0};
  std::thread thread_;
};

/// One service call as the caller saw it.
struct CallRecord {
  std::string what;  ///< "ping 5", "read_all 1", ...
  bool offline = false;
  bool returned = false;  ///< ServiceClient::call returned true
  bool success = false;   ///< online / success in the response
  bool as_expected = false;
  std::string message;
  double seconds = 0.0;
};

/// A thread of service calls with clients of its own. Owned through a shared_ptr held by the
/// thread too, so that a hung call can be abandoned (detached) without a dangling object.
class Caller {
 public:
  enum class Role { kOnlineLow, kOnlineHigh, kOffline };

  Caller(const std::string& ns, Role role) : nh_(ns), role_(role) {
    // Persistent: one connection per service and thread, so the master is not asked 300 times.
    ping_ = nh_.serviceClient<srd::ServoPing>("servo/ping", true);
    read_ = nh_.serviceClient<srd::ServoRead>("servo/read", true);
    write_ = nh_.serviceClient<srd::ServoWrite>("servo/write", true);
    read_angle_ = nh_.serviceClient<srd::ServoReadAngle>("servo/read_angle", true);
    read_all_ = nh_.serviceClient<srd::ServoReadAll>("servo/read_all", true);
  }

  static void start(const std::shared_ptr<Caller>& self) {
    self->thread_ = std::thread([self] { self->run(); });
  }
  bool done() const { return done_; }
  /// Joins when done, else abandons the thread (the test has failed then).
  void finish() {
    if (!thread_.joinable()) return;
    if (done_) {
      thread_.join();
    } else {
      thread_.detach();
    }
  }
  /// The calls completed so far (all of them once done()).
  std::vector<CallRecord> records() const {
    std::lock_guard<std::mutex> lock(records_mutex_);
    return records_;
  }
  std::size_t callsStarted() const { return started_; }

 private:
  void run() {
    const int calls = role_ == Role::kOffline ? kOfflineCalls : kOnlineCallsPerThread;
    for (int i = 0; i < calls; ++i) {
      ++started_;
      CallRecord record = role_ == Role::kOffline ? offlineCall(i) : onlineCall(i);
      std::lock_guard<std::mutex> lock(records_mutex_);
      records_.push_back(std::move(record));
    }
    done_ = true;
  }

  template <typename Srv>
  bool timedCall(ros::ServiceClient& client, Srv& srv, CallRecord* record) {
    const Clock::time_point start = Clock::now();
    record->returned = client.call(srv);
    record->seconds = test_support::secondsSince(start);
    return record->returned;
  }

  CallRecord offlineCall(int i) {
    CallRecord record;
    record.offline = true;
    const uint8_t id = (i / 2) % 2 == 0 ? kSilentId : kAbsentId;
    if (i % 2 == 0) {
      srd::ServoPing srv;
      srv.request.id = id;
      record.what = "ping " + std::to_string(id);
      if (timedCall(ping_, srv, &record)) {
        record.success = srv.response.online;
        record.message = srv.response.message;
      }
    } else {
      srd::ServoRead srv;
      srv.request.id = id;
      srv.request.param = "voltage";
      record.what = "read voltage " + std::to_string(id);
      if (timedCall(read_, srv, &record)) {
        record.success = srv.response.success;
        record.message = srv.response.message;
      }
    }
    record.as_expected = record.returned && !record.success &&
                         record.message.find("did not answer") != std::string::npos;
    return record;
  }

  CallRecord onlineCall(int i) {
    // The low thread owns servos 0 and 1, the high thread servo 2: each writes only its own, so
    // read_all can check the value it last wrote.
    const uint8_t id = role_ == Role::kOnlineLow ? kOnlineIds[(i / 5) % 2] : kOnlineIds[2];
    CallRecord record;
    switch (i % 5) {
      case 0: {
        srd::ServoPing srv;
        srv.request.id = kOnlineIds[i % kOnlineIds.size()];  // any online servo
        record.what = "ping " + std::to_string(srv.request.id);
        if (timedCall(ping_, srv, &record)) {
          record.success = srv.response.online;
          record.message = srv.response.message;
          record.as_expected = record.success;
        }
        break;
      }
      case 1: {
        srd::ServoRead srv;
        srv.request.id = id;
        srv.request.param = "voltage";
        record.what = "read voltage " + std::to_string(id);
        if (timedCall(read_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected =
              record.success && srv.response.unit == "mV" && srv.response.value > 0;
        }
        break;
      }
      case 2: {
        srd::ServoWrite srv;
        srv.request.id = id;
        srv.request.param = "soft_start_time";
        srv.request.value = 100 + i + (role_ == Role::kOnlineHigh ? 1000 : 0);
        record.what = "write soft_start_time " + std::to_string(id);
        if (timedCall(write_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected = record.success;
          if (record.success) written_[id] = srv.request.value;
        }
        break;
      }
      case 3: {
        srd::ServoReadAngle srv;
        srv.request.id = id;
        record.what = "read_angle " + std::to_string(id);
        if (timedCall(read_angle_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected = record.success && std::isfinite(srv.response.angle_deg);
        }
        break;
      }
      default: {
        srd::ServoReadAll srv;
        srv.request.id = id;
        record.what = "read_all " + std::to_string(id);
        if (timedCall(read_all_, srv, &record)) {
          record.success = srv.response.success;
          record.message = srv.response.message;
          record.as_expected = record.success && srv.response.names.size() == 22 &&
                               srv.response.values.size() == 22;
          const auto it = std::find(srv.response.names.begin(), srv.response.names.end(),
                                    "soft_start_time");
          if (record.as_expected && written_.count(id) > 0) {
            const bool found = it != srv.response.names.end();
            const int64_t value = found ? srv.response.values[it - srv.response.names.begin()] : -1;
            if (value != written_[id]) {
              record.as_expected = false;
              record.message += " [soft_start_time " + std::to_string(value) + ", last written " +
                                std::to_string(written_[id]) + "]";
            }
          }
        }
        break;
      }
    }
    return record;
  }

  ros::NodeHandle nh_;
  const Role role_;
  ros::ServiceClient ping_, read_, write_, read_angle_, read_all_;
  std::map<uint8_t, int64_t> written_;
  mutable std::mutex records_mutex_;
  std::vector<CallRecord> records_;
  std::atomic<std::size_t> started_{0};
  std::atomic<bool> done_{false};
  std::thread thread_;
};

double paramOr(const std::string& name, double fallback) {
  double value = fallback;
  ros::param::get(name, value);
  return value;
}

TEST(ServoStress, ServiceCallsNeverStallTheHeartbeatOrTelemetry) {
  const std::string node_name = "/servo_stress/driver_node";
  const std::string port = test_support::nodeParam(node_name, "port");
  ASSERT_FALSE(port.empty());
  const std::string port_status = "port " + port;
  const double servo_timeout = paramOr(node_name + "/servo_bus/timeout", 0.05);
  int servo_retries = 1;
  ros::param::get(node_name + "/servo_bus/retries", servo_retries);
  const double offline_bound = servo_timeout * (servo_retries + 1) + kOfflineMargin;
  ros::NodeHandle nh("servo_stress");
  ros::NodeHandle root;

  // Everything subscribed and connected before the robot exists, so no message is missed.
  TopicCounter<sensor_msgs::JointState> joints(nh, "joint_states", 1);
  DiagnosticsWatch diagnostics(root, "servo_stress/driver_node");
  Motion motion(nh);
  ASSERT_TRUE(joints.waitConnected(20));
  ASSERT_TRUE(motion.waitConnected());
  std::vector<std::shared_ptr<Caller>> callers = {
      std::make_shared<Caller>("servo_stress", Caller::Role::kOnlineLow),
      std::make_shared<Caller>("servo_stress", Caller::Role::kOnlineHigh),
      std::make_shared<Caller>("servo_stress", Caller::Role::kOffline)};
  ros::ServiceClient warm_up = nh.serviceClient<srd::ServoPing>("servo/ping");
  ASSERT_TRUE(warm_up.waitForExistence(ros::Duration(20)));
  ASSERT_TRUE(waitFor([&] { return diagnostics.latest(port_status).received > 0; }, 20))
      << "no diagnostics for the port";

  sim::SimOptions options;
  options.link = port;
  options.body.telemetry_rate_hz = kTelemetryRateHz;
  options.servo_bus.servo_ids = {kOnlineIds[0], kOnlineIds[1], kOnlineIds[2], kSilentId};
  options.servo_bus.offline_ids = {kSilentId};
  sim::RobotSim robot(options);
  robot.start();
  ASSERT_EQ(robot.ports().size(), 1u);

  // Warm-up: the port is open, wheel frames and telemetry flow, the bus answers.
  ASSERT_TRUE(waitFor([&] { return robot.stats().base.speed_frames_applied >= 5; }, 20))
      << "no wheel frames reached the simulated base";
  ASSERT_TRUE(joints.waitForCount(20, 20)) << "no joint_states";
  srd::ServoPing first_ping;
  first_ping.request.id = kOnlineIds[1];
  ASSERT_TRUE(warm_up.call(first_ping));
  ASSERT_TRUE(first_ping.response.online) << first_ping.response.message;
  motion.start();
  test_support::sleepSeconds(0.5);

  // --- the window opens: joint_states first, then the simulator (see the file comment) ---
  const uint64_t joints_open = joints.count();
  const sim::SimStats open = robot.stats();
  const Clock::time_point calls_started = Clock::now();
  for (const auto& caller : callers) Caller::start(caller);
  const bool all_returned = waitFor(
      [&] {
        return std::all_of(callers.begin(), callers.end(), [](const auto& c) { return c->done(); });
      },
      kCallDeadline);
  const double calls_s = test_support::secondsSince(calls_started);
  for (const auto& caller : callers) {
    EXPECT_TRUE(caller->done()) << "a service call hung: " << caller->callsStarted()
                                << " calls started by this thread within " << kCallDeadline << " s";
    caller->finish();
  }
  // Carry on after a hang: the completed calls and the counters below still say what went wrong.
  EXPECT_TRUE(all_returned) << "a service call never returned";

  // Every joint command published has reached the board before the simulator stops.
  motion.stop();
  const uint64_t joint_commands = motion.jointCommandsSent();
  waitFor([&] { return robot.stats().body.sync_writes_ok >= joint_commands; }, 10);

  // --- the window closes: stop the simulator, wait until nothing is in flight any more ---
  robot.stop();
  const sim::SimStats close = robot.stats();
  uint64_t still_polls = 0, seen = joints.count();
  waitFor(
      [&] {
        const uint64_t now = joints.count();
        still_polls = now == seen ? still_polls + 1 : 0;
        seen = now;
        return still_polls >= 10;  // 100 ms without a joint_state
      },
      10);
  const uint64_t joints_close = joints.count();
  // The node's counters once it has read everything: a diagnostics round after the rest.
  const uint64_t port_seen = diagnostics.latest(port_status).received;
  const auto port_final = diagnostics.waitFor(
      port_status, port_seen, [](const DiagnosticsWatch::Status&) { return true; },
      [] { return true; }, 10);
  ASSERT_TRUE(port_final.has_value()) << "no diagnostics after the run";
  const DiagnosticsWatch::Status base_status = diagnostics.latest("base");
  const DiagnosticsWatch::Status body_status = diagnostics.latest("body");
  const DiagnosticsWatch::Status servo_status =
      diagnostics.latest("servo_bus");

  // --- service calls ---
  std::vector<CallRecord> all;
  for (const auto& caller : callers) {
    const std::vector<CallRecord> records = caller->records();
    all.insert(all.end(), records.begin(), records.end());
  }
  uint64_t online = 0, online_ok = 0, offline = 0, offline_ok = 0, not_returned = 0;
  std::vector<double> offline_s;
  double slowest_online_s = 0.0;
  for (const CallRecord& call : all) {
    if (!call.returned) ++not_returned;
    if (call.offline) {
      ++offline;
      offline_s.push_back(call.seconds);
      if (call.as_expected && call.seconds <= offline_bound) ++offline_ok;
      EXPECT_TRUE(call.as_expected) << call.what << ": " << call.message;
      EXPECT_LE(call.seconds, offline_bound) << call.what << " took " << call.seconds << " s";
    } else {
      ++online;
      slowest_online_s = std::max(slowest_online_s, call.seconds);
      if (call.as_expected) ++online_ok;
      EXPECT_TRUE(call.as_expected) << call.what << " failed: " << call.message;
    }
  }
  std::sort(offline_s.begin(), offline_s.end());
  ASSERT_FALSE(offline_s.empty());
  std::printf("service calls: %zu in %.1f s from %zu threads; online %llu, %llu succeeded (slowest "
              "%.0f ms); offline %llu, %llu failed as expected\n",
              all.size(), calls_s, callers.size(), static_cast<unsigned long long>(online),
              static_cast<unsigned long long>(online_ok), 1000 * slowest_online_s,
              static_cast<unsigned long long>(offline),
              static_cast<unsigned long long>(offline_ok));
  std::printf("offline call durations: min %.0f ms, median %.0f ms, max %.0f ms (bound %.0f ms = "
              "%.0f ms x %d attempts + %.0f ms margin)\n",
              1000 * offline_s.front(), 1000 * offline_s[offline_s.size() / 2],
              1000 * offline_s.back(), 1000 * offline_bound, 1000 * servo_timeout,
              servo_retries + 1, 1000 * kOfflineMargin);
  std::printf("servo bus (node): %s transactions, %s timeouts, %s retries, %s mismatched, %s "
              "garbled, max latency %s ms\n",
              servo_status.value("transactions").c_str(), servo_status.value("timeouts").c_str(),
              servo_status.value("retries").c_str(),
              servo_status.value("mismatched answers").c_str(),
              servo_status.value("garbled answers").c_str(),
              servo_status.value("max latency (ms)").c_str());
  EXPECT_GE(all.size(), 300u);
  EXPECT_EQ(not_returned, 0u);
  EXPECT_EQ(online_ok, online);
  EXPECT_EQ(offline_ok, offline);
  EXPECT_EQ(close.servo_bus.malformed, 0u);

  // --- the wheel heartbeat, counted at the simulated base ---
  const double window_s = close.uptime_s - open.uptime_s;
  const uint64_t speed_frames = speedFramesReceived(close) - speedFramesReceived(open);
  const double expected_frames = window_s * kBaseLoopRateHz;
  std::printf("base: window %.1f s, %llu speed frames received by the simulator (%.0f at %.0f Hz), "
              "%llu resets, %llu FF errors sent, %llu heartbeat timeouts, %llu SEQ gaps; node: "
              "loop overruns %s, worst loop period %s ms\n",
              window_s, static_cast<unsigned long long>(speed_frames), expected_frames,
              kBaseLoopRateHz, static_cast<unsigned long long>(close.base.resets),
              static_cast<unsigned long long>(close.base.errors_sent),
              static_cast<unsigned long long>(close.base.timeouts),
              static_cast<unsigned long long>(close.base.seq_gaps),
              base_status.value("loop overruns").c_str(),
              base_status.value("worst loop period (ms)").c_str());
  EXPECT_EQ(close.base.errors_sent, 0u) << "the base's heartbeat expired";
  EXPECT_EQ(close.base.timeouts, 0u);
  EXPECT_EQ(close.base.resets, 1u) << "a Reset after the first: the node saw its own 1 s gap";
  EXPECT_EQ(close.base.speed_frames_ignored, 0u);
  EXPECT_EQ(close.base.seq_gaps, 0u) << "a wheel frame went missing between node and base";
  EXPECT_GE(static_cast<double>(speed_frames), 0.9 * expected_frames);
  EXPECT_GT(close.base.speed_frames_applied, 0u);

  // --- telemetry ---
  const int64_t sent_in_window = static_cast<int64_t>(telemetryIntact(close) -
                                                      telemetryIntact(open));
  const int64_t received_in_window = static_cast<int64_t>(joints_close - joints_open);
  const int64_t sent_total = static_cast<int64_t>(telemetryIntact(close));
  const int64_t received_total = static_cast<int64_t>(joints_close);
  const int64_t unread_bytes = static_cast<int64_t>(close.bytes_sent) -
                               static_cast<int64_t>(port_final->number("bytes in"));
  const auto& telemetry_counters =
      close.sent[static_cast<std::size_t>(sim::OutputKind::kTelemetry)];
  std::printf("telemetry: window: %lld frames sent intact, %lld joint_states received (in flight "
              "at the opening: %lld); whole run: %lld sent, %lld received, %lld lost, %lld bytes "
              "never read by the node; discarded by the simulator %llu\n",
              static_cast<long long>(sent_in_window), static_cast<long long>(received_in_window),
              static_cast<long long>(received_in_window - sent_in_window),
              static_cast<long long>(sent_total), static_cast<long long>(received_total),
              static_cast<long long>(sent_total - received_total),
              static_cast<long long>(unread_bytes),
              static_cast<unsigned long long>(telemetry_counters.discarded));
  EXPECT_GE(received_in_window, sent_in_window) << "telemetry frames were lost in the window";
  EXPECT_LE(received_in_window - sent_in_window, kOpeningInFlight);
  EXPECT_LE(received_total, sent_total) << "more joint_states than intact frames";
  EXPECT_GE(unread_bytes, 0);
  EXPECT_LE((sent_total - received_total) * static_cast<int64_t>(kTelemetryFrameBytes),
            unread_bytes)
      << "frames lost that the flush on open cannot explain";
  EXPECT_EQ(telemetry_counters.discarded, 0u) << "the node stopped reading its port";
  // One port session throughout: the node never lost or reopened its port.
  EXPECT_EQ(port_final->number("connects"), 1u);
  EXPECT_EQ(port_final->number("disconnects"), 0u);
  EXPECT_EQ(body_status.number("decode errors"), 0u);

  // --- joint commands and the host -> robot direction ---
  std::printf("joint commands: %llu published, %llu sync-writes applied by the board; cmd_vel: "
              "%llu published; host frames: %s out, checksum errors at the simulator %llu\n",
              static_cast<unsigned long long>(joint_commands),
              static_cast<unsigned long long>(close.body.sync_writes_ok),
              static_cast<unsigned long long>(motion.cmdVelSent()),
              port_final->value("frames out").c_str(),
              static_cast<unsigned long long>(close.framer.checksum_errors));
  EXPECT_EQ(close.body.sync_writes_ok, joint_commands);
  EXPECT_EQ(close.framer.checksum_errors, 0u);
  EXPECT_EQ(close.framer.bad_lengths, 0u);
  EXPECT_EQ(close.frames_for_absent_device, 0u);
  EXPECT_EQ(close.base.unknown_frames, 0u);
  EXPECT_EQ(close.body.sync_writes_malformed, 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_stress");
  return RUN_ALL_TESTS();
}
