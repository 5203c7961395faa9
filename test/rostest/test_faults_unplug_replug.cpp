// driver_node unplugged and replugged (faults.test): the test plays the robot by hand on a pty at
// /unplug/driver_node's port and closes and recreates it 100 times. After every replug the node
// must send a Reset before its first speed frame and publish exactly the telemetry frames written
// to it; across the cycles the node's open fds and threads must not grow (read from /proc/<pid>,
// the pid asked from the node itself), and it must hold exactly one pty fd while connected and
// none once the port is gone. Also the main() of the test_faults target.
#include <gtest/gtest.h>

#include "support/faults_support.h"

namespace {

using namespace faults_test;  // NOLINT: the shared fixture

// =================================================================================================
// Unplug / replug
// =================================================================================================

/// Plays the robot on a pty at `path` (from plug() on): a FakeDevice that records the base frames
/// the node writes in the current session.
std::unique_ptr<test_support::FakeDevice> handPlayedRobot(const std::string& path) {
  protocol::FramerConfig config;
  config.accept(srd::devices::base::kFrames);
  return std::make_unique<test_support::FakeDevice>(path, config);
}

/// The MSGID of every base frame of the current session.
std::vector<uint8_t> msgIds(const test_support::FakeDevice& robot) {
  std::vector<uint8_t> ids;
  for (const auto& frame : robot.frames()) {
    if (frame.family != srd::devices::base::kFrames || frame.bytes.size() < 5) continue;
    ids.push_back(frame.bytes[4]);  // 55 AA LEN SEQ MSGID ...
  }
  return ids;
}

void writeTelemetry(test_support::FakeDevice& robot, int frames) {
  srd::devices::body::Telemetry telemetry;
  telemetry.servo_count = 2;
  telemetry.servos[0].position = 2048;
  telemetry.servos[1].position = 1024;
  telemetry.imu[srd::devices::body::kAccelZ] = 2048;
  const std::vector<uint8_t> bytes = srd::devices::body::encodeTelemetry(telemetry);
  for (int i = 0; i < frames; ++i) robot.write(bytes);
}

TEST(UnplugReplug, HundredCyclesRecoverEveryTimeWithoutLeaks) {
  const std::string node_name = "/unplug/driver_node";
  const std::string path = test_support::nodeParam(node_name, "port");
  ASSERT_FALSE(path.empty());
  ros::NodeHandle nh("unplug");
  TopicCounter<sensor_msgs::JointState> joints(nh, "joint_states", 10);
  // Counted by the node, not only connected here: it builds joint_states only for subscribers it
  // counts, and every frame of the cycles must be published.
  ASSERT_TRUE(joints.waitCountedBy(node_name, 20));
  int pid = -1;
  ASSERT_TRUE(waitFor([&] { return (pid = test_support::nodePid(node_name)) > 0; }, 20));

  constexpr int kCycles = 100;
  constexpr int kWarmUpCycles = 5;  // ROS connections and lazy allocations settle first
  constexpr int kTelemetryPerCycle = 3;
  const std::unique_ptr<test_support::FakeDevice> robot = handPlayedRobot(path);
  test_support::ProcessSample warm;
  test_support::ProcessSample last;
  std::vector<double> recovery_s;
  for (int cycle = 1; cycle <= kCycles; ++cycle) {
    const auto plugged_at = test_support::Clock::now();
    robot->plug();
    // Recovery: the node reopens the port and sends a Reset before its first speed frame.
    const bool driving = waitFor(
        [&] {
          for (uint8_t id : msgIds(*robot)) {
            if (id == kMsgWheelSpeed) return true;
          }
          return false;
        },
        20);
    ASSERT_TRUE(driving) << "cycle " << cycle << ": no speed frame after the replug";
    recovery_s.push_back(test_support::secondsSince(plugged_at));
    const std::vector<uint8_t> ids = msgIds(*robot);
    ASSERT_EQ(ids.front(), kMsgReset) << "cycle " << cycle << ": the first frame is not a Reset";

    // Telemetry flows: every frame written after the node reopened the port is published.
    const uint64_t before = joints.count();
    writeTelemetry(*robot, kTelemetryPerCycle);
    ASSERT_TRUE(joints.waitForCount(before + kTelemetryPerCycle, 20))
        << "cycle " << cycle << ": " << joints.count() - before << " of " << kTelemetryPerCycle
        << " telemetry frames published";

    if (cycle == kWarmUpCycles) warm = test_support::sampleProcess(pid);
    if (cycle == kCycles) last = test_support::sampleProcess(pid);
    if (cycle == kWarmUpCycles || cycle == kCycles) {
      EXPECT_EQ(test_support::ptyFdCount(pid), 1u) << "cycle " << cycle << ": one port, one fd";
    }
    robot->unplug();
  }
  // Nothing more than what was written (no duplicates).
  test_support::sleepSeconds(0.2);
  EXPECT_EQ(joints.count(), static_cast<uint64_t>(kCycles * kTelemetryPerCycle));

  // Once the port is gone the node holds no pty fd at all.
  EXPECT_TRUE(waitFor([&] { return test_support::ptyFdCount(pid) == 0; }, 10))
      << test_support::ptyFdCount(pid) << " pty fds left open after the unplug";
  EXPECT_TRUE(test_support::processAlive(pid));

  double worst = 0, sum = 0;
  for (double s : recovery_s) {
    worst = std::max(worst, s);
    sum += s;
  }
  std::printf(
      "unplug/replug: %d cycles; fds %zu -> %zu, threads %zu -> %zu, RSS %ld -> %ld kB "
      "(after cycle %d -> after cycle %d); recovery mean %.0f ms, worst %.0f ms\n",
      kCycles, warm.fds, last.fds, warm.threads, last.threads, warm.rss_kb, last.rss_kb,
      kWarmUpCycles, kCycles, 1000 * sum / recovery_s.size(), 1000 * worst);
  // A tiny constant slack: a ROS connection (rosout, a master call) may be open at one sample
  // and not the other. A leak per cycle would show up as ~95 here.
  EXPECT_LE(last.fds, warm.fds + 2);
  EXPECT_LE(last.threads, warm.threads + 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_faults");
  return RUN_ALL_TESTS();
}
