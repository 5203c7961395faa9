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
#include <gtest/gtest.h>

#include "support/servo_stress_support.h"

namespace {

using namespace servo_stress_test;  // NOLINT: the shared fixture

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
  ASSERT_TRUE(ros::service::waitForService(nh.resolveName("servo/ping"), ros::Duration(20)));
  ASSERT_TRUE(waitFor([&] { return diagnostics.latest(port_status).received > 0; }, 20))
      << "no diagnostics for the port";

  sim::SimOptions options;
  options.link = port;
  srd::devices::body::sim::bodyConfig(options).telemetry_rate_hz = kTelemetryRateHz;
  srd::devices::servo_bus::sim::servoBusConfig(options).servo_ids = {kOnlineIds[0], kOnlineIds[1],
                                                                     kOnlineIds[2], kSilentId};
  srd::devices::servo_bus::sim::servoBusConfig(options).offline_ids = {kSilentId};
  sim::RobotSim robot(options);
  robot.start();
  ASSERT_EQ(robot.ports().size(), 1u);

  // Warm-up: the port is open, wheel frames and telemetry flow, the bus answers.
  ASSERT_TRUE(waitFor(
      [&] { return srd::devices::base::sim::baseStats(robot.stats()).speed_frames_applied >= 5; },
      20))
      << "no wheel frames reached the simulated base";
  ASSERT_TRUE(joints.waitForCount(20, 20)) << "no joint_states";
  srd::ServoPing first_ping;
  first_ping.request.id = kOnlineIds[1];
  ASSERT_TRUE(test_support::callService(nh.resolveName("servo/ping"), first_ping));
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
  waitFor(
      [&] {
        return srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok >= joint_commands;
      },
      10);

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
  const DiagnosticsWatch::Status servo_status = diagnostics.latest("servo_bus");

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
  std::printf(
      "service calls: %zu in %.1f s from %zu threads; online %llu, %llu succeeded (slowest "
      "%.0f ms); offline %llu, %llu failed as expected\n",
      all.size(), calls_s, callers.size(), static_cast<unsigned long long>(online),
      static_cast<unsigned long long>(online_ok), 1000 * slowest_online_s,
      static_cast<unsigned long long>(offline), static_cast<unsigned long long>(offline_ok));
  std::printf(
      "offline call durations: min %.0f ms, median %.0f ms, max %.0f ms (bound %.0f ms = "
      "%.0f ms x %d attempts + %.0f ms margin)\n",
      1000 * offline_s.front(), 1000 * offline_s[offline_s.size() / 2], 1000 * offline_s.back(),
      1000 * offline_bound, 1000 * servo_timeout, servo_retries + 1, 1000 * kOfflineMargin);
  std::printf(
      "servo bus (node): %s transactions, %s timeouts, %s retries, %s mismatched, %s "
      "garbled, max latency %s ms\n",
      servo_status.value("transactions").c_str(), servo_status.value("timeouts").c_str(),
      servo_status.value("retries").c_str(), servo_status.value("mismatched answers").c_str(),
      servo_status.value("garbled answers").c_str(),
      servo_status.value("max latency (ms)").c_str());
  EXPECT_GE(all.size(), 300u);
  EXPECT_EQ(not_returned, 0u);
  EXPECT_EQ(online_ok, online);
  EXPECT_EQ(offline_ok, offline);
  EXPECT_EQ(srd::devices::servo_bus::sim::servoBusStats(close).malformed, 0u);

  // --- the wheel heartbeat, counted at the simulated base ---
  const double window_s = close.uptime_s - open.uptime_s;
  const uint64_t speed_frames = speedFramesReceived(close) - speedFramesReceived(open);
  const double expected_frames = window_s * kBaseLoopRateHz;
  std::printf(
      "base: window %.1f s, %llu speed frames received by the simulator (%.0f at %.0f Hz), "
      "%llu resets, %llu FF errors sent, %llu heartbeat timeouts, %llu SEQ gaps; node: "
      "loop overruns %s, worst loop period %s ms\n",
      window_s, static_cast<unsigned long long>(speed_frames), expected_frames, kBaseLoopRateHz,
      static_cast<unsigned long long>(srd::devices::base::sim::baseStats(close).resets),
      static_cast<unsigned long long>(srd::devices::base::sim::baseStats(close).errors_sent),
      static_cast<unsigned long long>(srd::devices::base::sim::baseStats(close).timeouts),
      static_cast<unsigned long long>(srd::devices::base::sim::baseStats(close).seq_gaps),
      base_status.value("loop overruns").c_str(),
      base_status.value("worst loop period (ms)").c_str());
  EXPECT_EQ(srd::devices::base::sim::baseStats(close).errors_sent, 0u)
      << "the base's heartbeat expired";
  EXPECT_EQ(srd::devices::base::sim::baseStats(close).timeouts, 0u);
  EXPECT_EQ(srd::devices::base::sim::baseStats(close).resets, 1u)
      << "a Reset after the first: the node saw its own 1 s gap";
  EXPECT_EQ(srd::devices::base::sim::baseStats(close).speed_frames_ignored, 0u);
  EXPECT_EQ(srd::devices::base::sim::baseStats(close).seq_gaps, 0u)
      << "a wheel frame went missing between node and base";
  EXPECT_GE(static_cast<double>(speed_frames), 0.9 * expected_frames);
  EXPECT_GT(srd::devices::base::sim::baseStats(close).speed_frames_applied, 0u);

  // --- telemetry ---
  const int64_t sent_in_window =
      static_cast<int64_t>(telemetryIntact(close) - telemetryIntact(open));
  const int64_t received_in_window = static_cast<int64_t>(joints_close - joints_open);
  const int64_t sent_total = static_cast<int64_t>(telemetryIntact(close));
  const int64_t received_total = static_cast<int64_t>(joints_close);
  const int64_t unread_bytes =
      static_cast<int64_t>(close.bytes_sent) - static_cast<int64_t>(port_final->number("bytes in"));
  const auto& telemetry_counters = close.sentOf(srd::devices::body::sim::kTelemetryOutput);
  std::printf(
      "telemetry: window: %lld frames sent intact, %lld joint_states received (in flight "
      "at the opening: %lld); whole run: %lld sent, %lld received, %lld lost, %lld bytes "
      "never read by the node; discarded by the simulator %llu\n",
      static_cast<long long>(sent_in_window), static_cast<long long>(received_in_window),
      static_cast<long long>(received_in_window - sent_in_window),
      static_cast<long long>(sent_total), static_cast<long long>(received_total),
      static_cast<long long>(sent_total - received_total), static_cast<long long>(unread_bytes),
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
  std::printf(
      "joint commands: %llu published, %llu sync-writes applied by the board; cmd_vel: "
      "%llu published; host frames: %s out, checksum errors at the simulator %llu\n",
      static_cast<unsigned long long>(joint_commands),
      static_cast<unsigned long long>(srd::devices::body::sim::bodyStats(close).sync_writes_ok),
      static_cast<unsigned long long>(motion.cmdVelSent()), port_final->value("frames out").c_str(),
      static_cast<unsigned long long>(close.framer.checksum_errors));
  EXPECT_EQ(srd::devices::body::sim::bodyStats(close).sync_writes_ok, joint_commands);
  EXPECT_EQ(close.framer.checksum_errors, 0u);
  EXPECT_EQ(close.framer.bad_lengths, 0u);
  EXPECT_EQ(close.frames_for_absent_device, 0u);
  EXPECT_EQ(srd::devices::base::sim::baseStats(close).unknown_frames, 0u);
  EXPECT_EQ(srd::devices::body::sim::bodyStats(close).sync_writes_malformed, 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_servo_stress");
  return RUN_ALL_TESTS();
}
