// The whole simulated robot: shared and separate links, faults, baud-rate pacing, unplug/replug,
// the stats file and its thread's scheduling.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/framer_configs.h"
#include "support/realtime_support.h"
#include "support/sim_host.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::sim {
namespace {

using namespace sim_test;  // NOLINT: the shared fixture

// --- the whole robot -------------------------------------------------------------------------

/// The slice (ns) of this process's thread named `name`, from /proc; 0 when there is none.
uint64_t sliceOfThreadNamed(const std::string& name) {
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string comm;
    std::ifstream(task.path() / "comm") >> comm;
    if (comm == name) return test_support::sliceFromSchedFile(task.path() / "sched");
  }
  return 0;
}

// The boards answer as their microcontrollers would, on time: the simulator's one thread takes
// the fair scheduler's shortest slice, so a busy machine delays the simulated wheels little
// against the node's clock (test_imu_heading, test_odom compare the two).
TEST(RobotSim, ItsThreadRunsInTheShortestSchedulerSlice) {
  if (!test_support::ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  ASSERT_NE(test_support::currentThreadSliceNs(), 100000u) << "the test's thread has its own";
  TempDir dir;
  SimOptions options;
  options.link = dir.file("robot");
  RobotSim sim(options);
  sim.start();
  EXPECT_TRUE(test_support::waitFor([] { return sliceOfThreadNamed("robot_sim") == 100000u; }, 3.0))
      << "the thread named robot_sim: slice " << sliceOfThreadNamed("robot_sim") << " ns";
  sim.stop();
}

TEST(RobotSim, SharedPortCarriesAllThreeDevicesBehindTheLink) {
  TempDir dir;
  SimOptions options;
  options.link = dir.file("robot");
  RobotSim sim(options);
  sim.start();
  const auto ports = sim.ports();
  ASSERT_EQ(ports.size(), 1u);
  EXPECT_EQ(ports[0].devices, (std::vector<std::string>{"base", "body", "servo_bus"}));
  char target[256] = {};
  ASSERT_GT(::readlink(options.link.c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), ports[0].slave_path);

  Host host(options.link, test_support::driverFramer({"base", "body", "servo_bus"}, 2));
  ASSERT_TRUE(host.ok());
  host.send(kBatteryRequestSeq1);
  host.send({0x12, 0x4C, 0x01, 0x01, 0x01, 0x61});  // PING id 1
  EXPECT_TRUE(host.waitForFrame(kPing1Reply));
  EXPECT_TRUE(host.waitUntil([&] {
    return !host.framesOf(devices::base::kFrames).empty() &&
           host.framesOf(devices::body::kTelemetryFrames).size() >= 3;
  }));
  EXPECT_EQ(host.framesOf(devices::base::kFrames).at(0)[4], 0x02);  // the battery reply
}

TEST(RobotSim, DevicesWithTheirOwnLinksGetTheirOwnPtys) {
  TempDir dir;
  SimOptions options;
  options.device("base").link = dir.file("base");
  options.device("body").link = dir.file("body");
  options.device("servo_bus").link = dir.file("body");  // naming the same link: shared
  RobotSim sim(options);
  sim.start();
  const auto ports = sim.ports();
  ASSERT_EQ(ports.size(), 2u);
  EXPECT_EQ(ports[1].devices, (std::vector<std::string>{"body", "servo_bus"}));
  EXPECT_NE(ports[0].slave_path, ports[1].slave_path);

  Host base_host(dir.file("base"), baseHostConfig());
  ASSERT_TRUE(base_host.ok());
  base_host.send(kSyncWrite2And3);  // the board is not on this port
  base_host.send(kResetSeq2);
  ASSERT_TRUE(waitForStats(
      sim, [](const SimStats& s) { return devices::base::sim::baseStats(s).resets == 1; }));
  const SimStats stats = sim.stats();
  EXPECT_EQ(stats.frames_for_absent_device, 1u);
  EXPECT_EQ(devices::body::sim::bodyStats(stats).sync_writes_ok, 0u);
}

TEST(RobotSim, IntactFramesReceivedMatchTheSendCountersUnderFaults) {
  SimOptions options = onlyBody();
  devices::body::sim::bodyConfig(options).telemetry_rate_hz = 200;
  options.faults.seed = 7;
  options.faults.corrupt_rate = 0.2;
  options.faults.drop_rate = 0.2;
  options.faults.garbage_rate_hz = 30;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  host.waitUntil([&] { return host.framesOf(devices::body::kTelemetryFrames).size() >= 100; });
  sim.stop();  // the pty stays open: drain everything that was sent
  for (int i = 0; i < 10; ++i) host.pump(20);
  host.feedPadding();
  const SimStats stats = sim.stats();
  const SendCounters& telemetry = stats.sentOf(devices::body::sim::kTelemetryOutput);
  EXPECT_GT(telemetry.damaged, 0u);
  EXPECT_GT(stats.garbage_bursts, 0u);
  EXPECT_EQ(host.framesOf(devices::body::kTelemetryFrames).size(), telemetry.intact);
  EXPECT_EQ(telemetry.intact + telemetry.damaged + telemetry.discarded,
            devices::body::sim::bodyStats(stats).telemetry_generated);
}

// --pace-baud bounds can only be checked from one side without timing assertions: a paced line is
// never faster than its baud rate, however slow or busy the machine is.
TEST(RobotSim, PacedPortSendsNoFasterThanItsBaudRate) {
  SimOptions options = onlyBody();
  devices::body::sim::bodyConfig(options).telemetry_rate_hz =
      200;                   // several times what 9600 baud carries
  options.pace_baud = 9600;  // 960 bytes/s
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  for (int i = 0; i < 5; ++i) host.pump(20);  // what was sent before we listened
  const std::size_t before = host.bytesRead();
  const auto start = Clock::now();
  // Sent before the window, read during it: on a slow machine the pty holds more than one write.
  const std::size_t held_at_start = host.pending();
  host.waitUntil([&] { return host.bytesRead() - before >= 400; }, milliseconds(10000));
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  const std::size_t received = host.bytesRead() - before;
  EXPECT_GE(received, 400u);
  // What the line carried in that time, plus one write's worth in flight at the start.
  EXPECT_LE(static_cast<double>(received - std::min(received, held_at_start)),
            960.0 * elapsed_s + 16.0);
  EXPECT_FALSE(
      host.framesOf(devices::body::kTelemetryFrames).empty());  // cut into slices, not damaged
  EXPECT_EQ(host.framerStats().checksum_errors, 0u);
}

TEST(RobotSim, PacedPortTakesBytesInNoFasterThanItsBaudRate) {
  SimOptions options = onlyBody();
  devices::body::sim::bodyConfig(options).servo_ids = {2, 3};
  devices::body::sim::bodyConfig(options).telemetry_rate_hz = 0;
  options.pace_baud = 9600;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), bodyHostConfig(2));
  ASSERT_TRUE(host.ok());
  constexpr int kFrames = 6;
  const auto start = Clock::now();
  for (int i = 0; i < kFrames; ++i) host.send(kSyncWrite2And3);
  ASSERT_TRUE(waitForStats(
      sim,
      [](const SimStats& s) { return devices::body::sim::bodyStats(s).sync_writes_ok == kFrames; },
      milliseconds(10000)));
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  // The last frame reached the board only once all its bits were through the line.
  const double line_s = kFrames * kSyncWrite2And3.size() * 10.0 / 9600.0;
  EXPECT_GE(elapsed_s, line_s - 0.001);
}

// The answer of a paced servo comes after the request's bits, the servo's latency and the
// answer's bits, each on the line's clock: never sooner, and (checked by driver_bench, not here)
// not later either.
TEST(RobotSim, PacedServoAnswersAfterTheRequestTheLatencyAndTheAnswerOnTheLine) {
  SimOptions options = onlyServoBus();
  options.pace_baud = 9600;
  devices::servo_bus::sim::servoBusConfig(options).answer_latency_s = 0.005;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), servoHostConfig());
  ASSERT_TRUE(host.ok());
  for (int round = 0; round < 3; ++round) {
    host.frames().clear();
    const auto start = Clock::now();
    host.send(kReadAngle0);
    ASSERT_TRUE(host.waitForFrame(kReadAngle0ReplyZero, milliseconds(10000)));
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
    const double line_s = (kReadAngle0.size() + kReadAngle0ReplyZero.size()) * 10.0 / 9600.0;
    EXPECT_GE(elapsed_s, line_s + 0.005 - 0.0005);
  }
}

TEST(RobotSim, ServoFaultsGarbleOrSuppressAnswers) {
  SimOptions options = onlyServoBus();
  devices::servo_bus::sim::servoBusConfig(options).answer_fault_rate = 1.0;
  RobotSim sim(options);
  sim.start();
  Host host(slaveOf(sim), servoHostConfig());
  ASSERT_TRUE(host.ok());
  for (int i = 0; i < 20; ++i) host.send(kPing3);
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) {
    return devices::servo_bus::sim::servoBusStats(s).answers == 20;
  }));
  for (int i = 0; i < 5; ++i) host.pump(20);
  host.feedPadding();
  const SendCounters answers = sim.stats().sentOf(devices::servo_bus::sim::kServoAnswerOutput);
  EXPECT_EQ(answers.intact, 0u);
  EXPECT_GT(answers.suppressed, 0u);
  EXPECT_GT(answers.damaged, 0u);
  EXPECT_EQ(answers.suppressed + answers.damaged, 20u);
  EXPECT_EQ(host.countFrames(kPing3Reply), 0u);
}

TEST(RobotSim, UnplugRemovesTheLinkAndReplugRecreatesIt) {
  TempDir dir;
  SimOptions options = onlyBody();
  options.link = dir.file("robot");
  options.faults.unplug_every_s = 0.2;
  options.faults.unplug_duration_s = 0.3;
  std::mutex events_mutex;
  std::vector<std::string> events;
  options.on_event = [&](const std::string& text) {
    std::lock_guard<std::mutex> lock(events_mutex);
    events.push_back(text);
  };
  RobotSim sim(options);
  sim.start();
  struct stat info {};
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.unplugs >= 1; }));
  const bool link_gone = ::lstat(options.link.c_str(), &info) != 0;
  const bool still_unplugged = sim.stats().replugs == 0;
  if (still_unplugged) {
    EXPECT_TRUE(link_gone);
  }
  ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) { return s.replugs >= 1; }));
  sim.stop();
  char target[256] = {};
  ASSERT_GT(::readlink(options.link.c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), sim.ports().at(0).slave_path);
  std::lock_guard<std::mutex> lock(events_mutex);
  ASSERT_GE(events.size(), 2u);
  EXPECT_NE(events[0].find("unplugged"), std::string::npos);
}

TEST(RobotSim, StatsFileHasKeyValueLines) {
  TempDir dir;
  SimOptions options;
  options.stats_file = dir.file("stats");
  RobotSim sim(options);
  sim.start();
  {
    Host host(slaveOf(sim), baseHostConfig());
    ASSERT_TRUE(host.ok());
    host.send(kResetSeq2);
    ASSERT_TRUE(waitForStats(sim, [](const SimStats& s) {
      return devices::base::sim::baseStats(s).resets == 1 &&
             devices::body::sim::bodyStats(s).telemetry_generated > 2;
    }));
  }
  sim.stop();
  std::ifstream in(options.stats_file);
  ASSERT_TRUE(in.good());
  std::map<std::string, std::string> values;
  std::string key, value;
  while (in >> key >> value) values[key] = value;
  for (const char* expected :
       {"telemetry_sent_intact", "base_frames_received", "base_resets", "base_speed_frames_applied",
        "base_speed_frames_ignored", "base_errors_sent", "left_ticks", "right_ticks",
        "last_left_speed", "last_right_speed", "sync_writes_ok", "sync_writes_bad",
        "servo_1_position", "servo_2_position", "servo_requests", "bus_servo_0_angle_deg"}) {
    EXPECT_EQ(values.count(expected), 1u) << expected;
  }
  EXPECT_EQ(values["base_resets"], "1");
  EXPECT_NE(values["telemetry_sent_intact"], "0");
}

}  // namespace
}  // namespace serial_robot_driver::sim
