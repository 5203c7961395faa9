// Soak of driver_node under injected faults, with every counter reconciled afterwards.
//
// soak.test launches /soak/driver_node with the base, the body and the servo bus on one port. This
// test plays the robot with the simulator library (sim::RobotSim) in its own process, so it can
// read the simulator's counters at any moment, with garbage bursts, corrupted checksums, dropped
// bytes, garbled or missing servo answers and an unplug every few seconds. Meanwhile it publishes
// cmd_vel and joint_commands and calls the servo and base services.
//
// How the telemetry is reconciled, exactly where it can be:
//  An episode runs from one unplug to the next. While the pty is unplugged the simulator's counters
//  are frozen and the driver's port is down, so both sides can be read at rest: the simulator's
//  intact telemetry frames and bytes written, the driver's bytes read (its /diagnostics port
//  status, once it reports the port down with the matching disconnect count) and the joint_states
//  this test received. Per episode:
//    received <= sent        (a damaged frame is never published: no false positive)
//    flushed = bytes written by the simulator - bytes read by the driver, >= 0
//    lost = sent - received, and 32 * lost <= flushed (a telemetry frame is >= 32 bytes)
//  so lost == 0 exactly whenever no byte went unread. Bytes go unread for one reason in normal
//  operation: the driver flushes the port when it opens it (tcflush), discarding what the simulator
//  wrote into the new pty before the driver reopened it (up to one reconnect interval of traffic
//  after each replug); and, if the driver were too slow, what it had not read when the
//  simulator's 250 ms drain wait before an unplug ran out. The simulator drains before every
//  unplug, so the end of an episode is exact. The one way the bound could be broken without a
//  driver bug is a garbage burst that forms a plausible frame start in the very last bytes before
//  an unplug and hides an intact frame from the framer when it is reset: it needs a random header
//  match there and has not been observed. imu/data and telemetry must match joint_states one for
//  one.
//
// Host -> robot frames are reconciled against the driver's own "frames out": the simulator
// received them all, except frames written into the pty in the instant between the simulator's
// last read and its close of the master (a few per unplug at most); none arrives corrupted or at a
// port without its device. The base never ignores a speed frame (a Reset always came first after
// every reconnect), every joint command is accounted for (sent, failed write or rejected), every
// service call returns. The node's RSS, open fds and threads stay flat, and it is the same process
// at the end.
#include <gtest/gtest.h>

#include "support/soak_support.h"

namespace {

using namespace soak_test;  // NOLINT: the shared fixture

TEST(Soak, FaultsForAMinuteAndEveryCounterReconciles) {
  const std::string node_name = "/soak/driver_node";
  const std::string port = test_support::nodeParam(node_name, "port");
  ASSERT_FALSE(port.empty());
  const std::string port_status = "port " + port;
  ros::NodeHandle nh("soak");
  ros::NodeHandle root;

  // Everything subscribed before the robot exists, so no message is missed.
  TopicCounter<sensor_msgs::JointState> joints(nh, "joint_states", 1);
  TopicCounter<sensor_msgs::Imu> imu(nh, "imu/data", 1);
  TopicCounter<srd::Telemetry> telemetry(nh, "telemetry", 1);
  TopicCounter<srd::WheelCommand> wheels(nh, "wheel_command", 1);
  DiagnosticsWatch diagnostics(root, "soak/driver_node");
  Motion motion(nh);
  ServiceCaller services(nh);
  ASSERT_TRUE(joints.waitConnected(20) && imu.waitConnected(20) && telemetry.waitConnected(20) &&
              wheels.waitConnected(20));
  // The node counts a subscriber a little after it is connected, and the counts below are exact.
  ASSERT_TRUE(joints.waitCountedBy(node_name, 20) && imu.waitCountedBy(node_name, 20) &&
              telemetry.waitCountedBy(node_name, 20) && wheels.waitCountedBy(node_name, 20));
  ASSERT_TRUE(motion.waitConnected());
  ASSERT_TRUE(services.waitConnected());
  ASSERT_TRUE(waitFor([&] { return diagnostics.latest(port_status).received > 0; }, 20))
      << "no diagnostics for the port";
  int pid = -1;
  ASSERT_TRUE(waitFor([&] { return (pid = test_support::nodePid(node_name)) > 0; }, 20));
  ASSERT_EQ(diagnostics.latest(port_status).number("bytes in"), 0u);

  sim::SimOptions options;
  options.link = port;
  srd::devices::body::sim::bodyConfig(options).foot_mode =
      srd::devices::body::sim::FootMode::kAlternate;
  srd::devices::body::sim::bodyConfig(options).imu_noise = true;
  options.faults.seed = 20240611;
  options.faults.garbage_rate_hz = 5.0;
  options.faults.corrupt_rate = 0.02;
  options.faults.drop_rate = 0.02;
  srd::devices::servo_bus::sim::servoBusConfig(options).answer_fault_rate = 0.1;
  options.faults.unplug_every_s = kUnplugEvery;
  options.faults.unplug_duration_s = kUnplugDuration;
  sim::RobotSim robot(options);
  robot.start();
  motion.start();
  services.start();

  const double soak_s = soakSeconds();
  const auto started = test_support::Clock::now();
  std::vector<Boundary> boundaries;
  uint64_t handled_unplugs = 0;
  uint64_t skipped_boundaries = 0;
  const auto unpluggedAt = [&](uint64_t k) {
    const sim::SimStats s = robot.stats();
    return !robot.ports().at(0).plugged && s.unplugs == k && s.replugs + 1 == k;
  };
  // Until the soak time is over and one more boundary has been captured after it.
  while (boundaries.empty() || test_support::secondsSince(started) < soak_s ||
         boundaries.back().sim.uptime_s < soak_s) {
    if (test_support::secondsSince(started) > soak_s + 4 * (kUnplugEvery + kUnplugDuration)) break;
    test_support::sleepSeconds(0.02);
    const sim::SimStats s = robot.stats();
    if (s.unplugs == handled_unplugs || !unpluggedAt(s.unplugs)) continue;
    const uint64_t k = s.unplugs;
    handled_unplugs = k;
    // The driver's own view once it has seen the loss: port down, k disconnects.
    const auto status = diagnostics.waitFor(
        port_status, 0,
        [k](const DiagnosticsWatch::Status& st) {
          return !st.flag("connected") && st.number("disconnects") == k;
        },
        [&] { return unpluggedAt(k); }, 5.0);
    // Messages published before the loss may still be on their way (local TCP, a busy machine):
    // the port is down, so nothing new can come; wait until the counts have been still a while.
    uint64_t still_polls = 0, seen = joints.count() + imu.count() + telemetry.count();
    while (status && still_polls < 3 && unpluggedAt(k)) {
      test_support::sleepSeconds(0.1);
      const uint64_t now = joints.count() + imu.count() + telemetry.count();
      still_polls = now == seen ? still_polls + 1 : 0;
      seen = now;
    }
    Boundary boundary;
    boundary.joint_states = joints.count();
    boundary.imu = imu.count();
    boundary.telemetry = telemetry.count();
    boundary.process = test_support::sampleProcess(pid);
    if (!status || !unpluggedAt(k)) {
      ++skipped_boundaries;  // the episode merges with the next one
      continue;
    }
    boundary.unplugs = k;
    boundary.sim = robot.stats();
    boundary.port = *status;
    boundaries.push_back(boundary);
  }
  motion.stop();
  services.stop();
  const double soaked_s = test_support::secondsSince(started);
  ASSERT_GE(boundaries.size(), 2u) << "too few unplugs observed";
  EXPECT_LE(skipped_boundaries, boundaries.size() / 2) << "most unplugs were not observed at rest";
  EXPECT_TRUE(test_support::processAlive(pid)) << "driver_node died";
  EXPECT_EQ(test_support::nodePid(node_name), pid) << "driver_node was restarted";

  // --- telemetry, episode by episode ---
  std::printf("soak: %.0f s, %zu episodes reconciled (%llu unplugs not seen at rest, merged)\n",
              soaked_s, boundaries.size(), static_cast<unsigned long long>(skipped_boundaries));
  std::printf("%8s %8s %8s %6s %9s %9s\n", "unplugs", "sent", "received", "lost", "flushed B",
              "pub. imu");
  Boundary previous;  // zero: nothing sent, read or received before the robot started
  uint64_t total_sent = 0, total_received = 0, total_flushed = 0, exact_episodes = 0;
  for (const Boundary& b : boundaries) {
    const uint64_t sent = telemetryIntact(b.sim) - telemetryIntact(previous.sim);
    const uint64_t received = b.joint_states - previous.joint_states;
    const int64_t written = static_cast<int64_t>(b.sim.bytes_sent - previous.sim.bytes_sent);
    const int64_t read =
        static_cast<int64_t>(b.port.number("bytes in") - previous.port.number("bytes in"));
    const int64_t flushed = written - read;
    const int64_t lost = static_cast<int64_t>(sent) - static_cast<int64_t>(received);
    std::printf("%8llu %8llu %8llu %6lld %9lld %9llu\n", static_cast<unsigned long long>(b.unplugs),
                static_cast<unsigned long long>(sent), static_cast<unsigned long long>(received),
                static_cast<long long>(lost), static_cast<long long>(flushed),
                static_cast<unsigned long long>(b.imu - previous.imu));
    EXPECT_LE(received, sent) << "episode ending at unplug " << b.unplugs
                              << ": more joint_states than intact frames";
    EXPECT_GE(flushed, 0) << "the driver read more bytes than were written";
    EXPECT_LE(lost * static_cast<int64_t>(kShortestTelemetryFrame), flushed)
        << "episode ending at unplug " << b.unplugs << ": " << lost
        << " intact frames lost but only " << flushed << " bytes went unread";
    EXPECT_EQ(b.imu, b.joint_states);
    EXPECT_EQ(b.telemetry, b.joint_states);
    // The driver opened the port once per episode and lost it once per unplug.
    EXPECT_EQ(b.port.number("connects"), b.unplugs);
    EXPECT_EQ(b.port.number("disconnects"), b.unplugs);
    if (lost == 0) ++exact_episodes;
    total_sent += sent;
    total_received += received;
    total_flushed += static_cast<uint64_t>(std::max<int64_t>(flushed, 0));
    previous = b;
  }
  const Boundary& last = boundaries.back();
  std::printf(
      "telemetry: %llu intact frames sent, %llu joint_states received, %llu lost to the "
      "flush on open (%llu bytes unread); %llu of %zu episodes exact\n",
      static_cast<unsigned long long>(total_sent), static_cast<unsigned long long>(total_received),
      static_cast<unsigned long long>(total_sent - total_received),
      static_cast<unsigned long long>(total_flushed),
      static_cast<unsigned long long>(exact_episodes), boundaries.size());
  const auto tel = last.sim.sentOf(srd::devices::body::sim::kTelemetryOutput);
  std::printf(
      "simulator: telemetry damaged %llu, discarded %llu; garbage bursts %llu (%llu B); "
      "driver: checksum errors %s, bytes skipped %s\n",
      static_cast<unsigned long long>(tel.damaged), static_cast<unsigned long long>(tel.discarded),
      static_cast<unsigned long long>(last.sim.garbage_bursts),
      static_cast<unsigned long long>(last.sim.garbage_bytes),
      last.port.value("checksum errors").c_str(),
      last.port.value("bytes skipped (resync)").c_str());
  EXPECT_GT(tel.damaged, 0u) << "the faults did not happen";
  EXPECT_GT(last.sim.garbage_bursts, 0u);
  EXPECT_GT(total_received, 0u);

  // --- host -> robot ---
  const uint64_t frames_out = last.port.number("frames out");
  const uint64_t frames_in = hostFramesReceived(last.sim);
  std::printf(
      "host frames: driver wrote %llu, simulator received %llu (lost at %llu unplugs: "
      "%lld)\n",
      static_cast<unsigned long long>(frames_out), static_cast<unsigned long long>(frames_in),
      static_cast<unsigned long long>(last.unplugs),
      static_cast<long long>(frames_out) - static_cast<long long>(frames_in));
  EXPECT_LE(frames_in, frames_out);
  EXPECT_LE(frames_out - std::min(frames_out, frames_in),
            kMaxHostFramesLostPerUnplug * last.unplugs);
  EXPECT_EQ(last.sim.framer.checksum_errors, 0u) << "a host frame arrived corrupted";
  EXPECT_EQ(last.sim.framer.bad_lengths, 0u);
  EXPECT_EQ(last.sim.frames_for_absent_device, 0u);
  EXPECT_EQ(srd::devices::base::sim::baseStats(last.sim).unknown_frames, 0u);
  EXPECT_EQ(srd::devices::body::sim::bodyStats(last.sim).sync_writes_malformed, 0u);
  EXPECT_EQ(srd::devices::servo_bus::sim::servoBusStats(last.sim).malformed, 0u);
  // After every reconnect the Reset came before the first speed frame: the base, in its heartbeat
  // error state after each unplug, never had to ignore a speed frame.
  EXPECT_EQ(srd::devices::base::sim::baseStats(last.sim).speed_frames_ignored, 0u);
  EXPECT_GE(srd::devices::base::sim::baseStats(last.sim).timeouts,
            last.unplugs - 1);  // every unplug outlasted the heartbeat
  EXPECT_GT(srd::devices::base::sim::baseStats(last.sim).speed_frames_applied, 0u);
  EXPECT_LE(srd::devices::base::sim::baseStats(last.sim).speed_frames_applied, wheels.count());
  std::printf(
      "base: %llu wheel frames published, %llu applied by the base, %llu resets received, "
      "%llu heartbeat timeouts, %llu battery requests\n",
      static_cast<unsigned long long>(wheels.count()),
      static_cast<unsigned long long>(
          srd::devices::base::sim::baseStats(last.sim).speed_frames_applied),
      static_cast<unsigned long long>(srd::devices::base::sim::baseStats(last.sim).resets),
      static_cast<unsigned long long>(srd::devices::base::sim::baseStats(last.sim).timeouts),
      static_cast<unsigned long long>(
          srd::devices::base::sim::baseStats(last.sim).battery_requests));

  // Every joint command is accounted for by the node (diagnostics once a second).
  const uint64_t commands = motion.jointCommandsSent();
  const auto body = diagnostics.waitFor(
      "body", 0,
      [&](const DiagnosticsWatch::Status& s) {
        return s.number("commands sent") + s.number("command write failures") +
                   s.number("commands rejected") >=
               commands;
      },
      [] { return true; }, 10);
  ASSERT_TRUE(body.has_value()) << "the node did not account for all " << commands
                                << " joint commands";
  std::printf(
      "joint commands: %llu published, %llu sent, %llu failed (port down), %llu rejected; "
      "simulator applied %llu; telemetry decode errors %s\n",
      static_cast<unsigned long long>(commands),
      static_cast<unsigned long long>(body->number("commands sent")),
      static_cast<unsigned long long>(body->number("command write failures")),
      static_cast<unsigned long long>(body->number("commands rejected")),
      static_cast<unsigned long long>(
          srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok),
      body->value("decode errors").c_str());
  EXPECT_EQ(body->number("commands sent") + body->number("command write failures"), commands);
  EXPECT_EQ(body->number("commands rejected"), 0u);
  EXPECT_EQ(body->number("decode errors"), 0u);
  EXPECT_LE(srd::devices::body::sim::bodyStats(robot.stats()).sync_writes_ok,
            body->number("commands sent"));

  // Every service call returned, and every failure said why.
  const sim::SimStats final_sim = robot.stats();
  const uint64_t servo_answers =
      final_sim.sentOf(srd::devices::servo_bus::sim::kServoAnswerOutput).intact;
  std::printf(
      "services: %llu calls, %llu succeeded, %llu failed with a reason, slowest %.0f ms; "
      "servo answers sent intact %llu, garbled %llu, withheld %llu\n",
      static_cast<unsigned long long>(services.calls),
      static_cast<unsigned long long>(services.successes),
      static_cast<unsigned long long>(services.failures), 1000 * services.slowest_s,
      static_cast<unsigned long long>(servo_answers),
      static_cast<unsigned long long>(
          final_sim.sentOf(srd::devices::servo_bus::sim::kServoAnswerOutput).damaged),
      static_cast<unsigned long long>(
          final_sim.sentOf(srd::devices::servo_bus::sim::kServoAnswerOutput).suppressed));
  EXPECT_EQ(services.call_failures, 0u);
  EXPECT_EQ(services.silent_failures, 0u);
  EXPECT_GT(services.answered_successes, 0u);
  EXPECT_LE(services.answered_successes, servo_answers);

  // Flat resources, compared at rest (port down) at the first and the last boundary.
  const test_support::ProcessSample& first = boundaries.front().process;
  const test_support::ProcessSample& end = last.process;
  std::printf(
      "driver_node (pid %d): RSS %ld -> %ld kB, fds %zu -> %zu, threads %zu -> %zu, "
      "pty fds %zu -> %zu\n",
      pid, first.rss_kb, end.rss_kb, first.fds, end.fds, first.threads, end.threads, first.pty_fds,
      end.pty_fds);
  EXPECT_GT(first.rss_kb, 0);
  EXPECT_LE(end.rss_kb, first.rss_kb + kRssSlackKb);
  EXPECT_LE(end.fds, first.fds + 2);  // a service connection may be open at either moment
  EXPECT_LE(end.threads, first.threads + 1);
  EXPECT_EQ(end.pty_fds, 0u) << "the lost port's fd is still open";
  robot.stop();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_soak");
  return RUN_ALL_TESTS();
}
