// driver_node processes this test starts itself (base_node.test): a port that appears later, a bad
// parameter, SIGINT while driving, a node that starts with the e-stop engaged, the threads'
// priorities with ~realtime_priority; and the main() of the test_base_node target.
#include <gtest/gtest.h>
#include <sched.h>
#include <std_msgs/Bool.h>

#include <fstream>

#include "support/base_node_fixture.h"
#include "support/realtime_support.h"

namespace {

using namespace base_node_test;  // NOLINT: the shared fixture

/// A driver_node of the test's own, named `driver_<name>` in namespace `/<name>` on a FakeBase of
/// its own port, with one extra parameter; `ready()` once its cmd_vel is subscribed.
struct OwnDriver {
  OwnDriver(const std::string& name, const std::string& extra_param)
      : base(g_port + "_" + name),
        node(g_driver_path,
             withParam(driverArgs("/" + name, "driver_" + name, g_port + "_" + name), extra_param)),
        cmd_vel(g_ros->nh().advertise<geometry_msgs::Twist>("/" + name + "/cmd_vel", 10)) {}
  static std::vector<std::string> withParam(std::vector<std::string> args,
                                            const std::string& param) {
    args.push_back(param);
    return args;
  }
  bool ready() {
    return node.started() && waitFor([&] { return cmd_vel.getNumSubscribers() > 0; }, 20.0);
  }
  FakeBase base;
  ChildProcess node;
  ros::Publisher cmd_vel;
};

// 12. A node started while its port does not exist yet keeps retrying and connects when the
// device appears, starting with a Reset.
TEST(BaseNodeProcess, ConnectsWhenThePortAppearsLater) {
  ASSERT_FALSE(g_driver_path.empty());
  const std::string port = g_port + "_late";
  test_support::removeStaleLink(port);
  ChildProcess node(g_driver_path, driverArgs("/late", "driver_late", port));
  ASSERT_TRUE(node.started());
  // Up and failing to open its port (its services exist once the base interface is built).
  ASSERT_TRUE(ros::service::waitForService("/late/base/reset", 20000)) << node.output();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_TRUE(node.running()) << node.output();

  FakeBase base(port);
  ASSERT_TRUE(base.waitForCount(2, 10.0)) << "no frames after the port appeared\n" << node.output();
  const std::vector<SeenFrame> frames = base.frames();
  EXPECT_EQ(frames[0].bytes, resetFrame(frames[0].seq));
  EXPECT_TRUE(frames[1].isSpeed());

  node.signal(SIGTERM);
  const auto status = node.waitExit(10.0);
  ASSERT_TRUE(status.has_value()) << "driver_node did not exit on SIGTERM";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << node.output();
}

// 13. A bad parameter stops the node at start-up with a non-zero status and names the parameter.
// A speed limit of 0 is one: it would not mean "no limit".
TEST(BaseNodeProcess, BadParameterExitsNamingIt) {
  ASSERT_FALSE(g_driver_path.empty());
  const std::vector<std::pair<std::string, std::string>> cases = {{"base/wheel_diameter", "-1"},
                                                                  {"base/max_wheel_speed", "0.0"},
                                                                  {"base/max_wheel_speed", "-0.5"}};
  int run = 0;
  for (const auto& [name, value] : cases) {
    SCOPED_TRACE(name + " " + value);
    // A node name of its own each time: `_name:=value` stays on the parameter server.
    std::vector<std::string> args =
        driverArgs("/bad", "driver_bad" + std::to_string(run++), g_port + "_bad");
    args.push_back("_" + name + ":=" + value);
    ChildProcess node(g_driver_path, args);
    ASSERT_TRUE(node.started());
    const auto status = node.waitExit(20.0);
    ASSERT_TRUE(status.has_value()) << "driver_node kept running with " << name << " " << value;
    ASSERT_TRUE(WIFEXITED(*status)) << node.output();
    EXPECT_EQ(WEXITSTATUS(*status), 2);
    EXPECT_NE(node.output().find(name), std::string::npos) << node.output();
  }
}

// 14. SIGINT while driving: the node's last frame before it closes the port is a zero-speed frame,
// and it exits cleanly.
TEST(BaseNodeProcess, SigintStopsTheWheelsBeforeExit) {
  ASSERT_FALSE(g_driver_path.empty());
  const std::string port = g_port + "_sigint";
  FakeBase base(port);
  ChildProcess node(g_driver_path, driverArgs("/sig", "driver_sigint", port));
  ASSERT_TRUE(node.started());
  ros::Publisher cmd_vel = g_ros->nh().advertise<geometry_msgs::Twist>("/sig/cmd_vel", 10);
  ASSERT_TRUE(waitFor([&] { return cmd_vel.getNumSubscribers() > 0; }, 20.0)) << node.output();

  CmdVelStreamer streamer(cmd_vel);
  streamer.set(0.5, 0.0);  // 20.37 ticks per period
  ASSERT_TRUE(base.waitUntil(
      [](const std::vector<SeenFrame>& frames) {
        const auto first = firstMoving(frames, 0);
        return first && speedCount(frames, *first) >= 10;
      },
      10.0))
      << node.output();

  node.signal(SIGINT);  // the streamer keeps going: the stop must come from the shutdown
  const auto status = node.waitExit(10.0);
  streamer.stop(false);
  ASSERT_TRUE(status.has_value()) << "driver_node did not exit on SIGINT";
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << node.output();

  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the last bytes
  const std::vector<SeenFrame> speed = speedFramesFrom(base.frames(), 0);
  ASSERT_GE(speed.size(), 2u);
  const SeenFrame& last = speed.back();
  const SeenFrame& before_last = speed[speed.size() - 2];
  EXPECT_EQ(last.bytes, zeroSpeedFrame(last.seq));
  EXPECT_EQ(last.seq, static_cast<uint8_t>(before_last.seq + 1));
  EXPECT_FALSE(before_last.isZeroSpeed()) << "the wheels had already stopped before the SIGINT";
  EXPECT_EQ(base.frames().back().bytes, last.bytes);
  EXPECT_EQ(base.garbage(), 0u);
}

// 15. ~e_stop/start_engaged: a respawned driver comes back stopped. cmd_vel streams from the
// start, yet every speed frame is zero until an e_stop false arrives; only then does it drive.
TEST(BaseNodeProcess, StartEngagedHoldsTheBaseUntilReleased) {
  ASSERT_FALSE(g_driver_path.empty());
  OwnDriver driver("engaged", "_e_stop/start_engaged:=true");
  FakeBase& base = driver.base;
  ChildProcess& node = driver.node;
  ros::Publisher& cmd_vel = driver.cmd_vel;
  ros::Publisher e_stop = g_ros->nh().advertise<std_msgs::Bool>("/engaged/e_stop", 1, true);
  ASSERT_TRUE(driver.ready()) << node.output();

  CmdVelStreamer streamer(cmd_vel);
  streamer.set(0.5, 0.0);
  // 50 speed frames (1 s at 50 Hz) while cmd_vel streams: not one may move a wheel.
  ASSERT_TRUE(base.waitUntil(
      [](const std::vector<SeenFrame>& frames) { return speedCount(frames, 0) >= 50; }, 10.0))
      << node.output();
  EXPECT_FALSE(firstMoving(base.frames(), 0).has_value()) << "drove before the release";

  const std::size_t released_at = base.count();
  std_msgs::Bool release;
  release.data = false;
  e_stop.publish(release);
  EXPECT_TRUE(base.waitUntil(
      [&](const std::vector<SeenFrame>& frames) {
        return firstMoving(frames, released_at).has_value();
      },
      10.0))
      << "a cmd_vel after the release did not drive\n"
      << node.output();

  streamer.stop(true);
  node.signal(SIGTERM);
  EXPECT_TRUE(node.waitExit(10.0).has_value()) << "driver_node did not exit on SIGTERM";
}

/// A thread's name and its scheduling policy, priority and slice, as the kernel holds them.
struct NodeThread {
  std::string name;
  int policy = -1;
  int priority = -1;
  uint64_t slice_ns = 0;  ///< `se.slice` of /proc/<pid>/task/<tid>/sched
};

std::vector<NodeThread> nodeThreads(pid_t pid) {
  std::vector<NodeThread> threads;
  const std::string tasks = "/proc/" + std::to_string(pid) + "/task/";
  for (const std::string& tid : test_support::listDirectory(tasks)) {
    NodeThread thread;
    std::ifstream(tasks + tid + "/comm") >> thread.name;
    thread.policy = sched_getscheduler(std::stoi(tid));
    sched_param param{};
    if (sched_getparam(std::stoi(tid), &param) == 0) thread.priority = param.sched_priority;
    thread.slice_ns = test_support::sliceFromSchedFile(tasks + tid + "/sched");
    threads.push_back(thread);
  }
  return threads;
}

// 16. ~realtime_priority where this process may use SCHED_FIFO (root in a container): the
// threads that carry frames (the port's reader, the base loop) run at the priority, every other
// thread of the node (roscpp's, the spinners) one below, so a frame thread that wakes preempts
// them instead of waiting for one to block.
TEST(BaseNodeProcess, RealtimeFrameThreadsRunAboveTheRestOfTheNode) {
  ASSERT_FALSE(g_driver_path.empty());
  if (!test_support::fifoAllowed(30)) GTEST_SKIP() << "this process may not use SCHED_FIFO";
  OwnDriver driver("rt", "_realtime_priority:=30");
  FakeBase& base = driver.base;
  ChildProcess& node = driver.node;
  ASSERT_TRUE(driver.ready()) << node.output();
  ASSERT_TRUE(base.waitForCount(2, 10.0)) << node.output();  // the reader and the loop run

  std::size_t frame_threads = 0;
  for (const NodeThread& thread : nodeThreads(node.pid())) {
    SCOPED_TRACE(thread.name);
    const bool carries_frames = thread.name == "srd_reader" || thread.name == "srd_base_loop";
    frame_threads += carries_frames ? 1 : 0;
    EXPECT_EQ(thread.policy, SCHED_FIFO);
    EXPECT_EQ(thread.priority, carries_frames ? 30 : 29);
  }
  EXPECT_EQ(frame_threads, 2u) << "one port reader and the base loop";
  node.signal(SIGTERM);
  EXPECT_TRUE(node.waitExit(10.0).has_value()) << "driver_node did not exit on SIGTERM";
}

// 17. ~scheduler_slice_us: by default every thread of the node, roscpp's included (the main thread
// asks before roscpp starts them), runs in 100 us turns, so a woken thread preempts a CPU hog at
// once; with 0 every thread keeps the kernel's slice.
TEST(BaseNodeProcess, EveryThreadTakesTheSchedulerSliceByDefault) {
  ASSERT_FALSE(g_driver_path.empty());
  if (!test_support::ownSlicesKept()) GTEST_SKIP() << test_support::kNoOwnSlices;
  const uint64_t kernel_slice = test_support::currentThreadSliceNs();
  ASSERT_NE(kernel_slice, 100000u) << "this test thread must have the kernel's slice";
  // The default case passes an unrelated parameter at its default: OwnDriver takes one.
  for (const char* slice_param : {"_capture:=false", "_scheduler_slice_us:=0"}) {
    SCOPED_TRACE(slice_param);
    OwnDriver driver("slice", slice_param);
    ChildProcess& node = driver.node;
    ASSERT_TRUE(driver.ready()) << node.output();
    ASSERT_TRUE(driver.base.waitForCount(2, 10.0)) << node.output();  // the reader and the loop run
    const std::vector<NodeThread> threads = nodeThreads(node.pid());
    EXPECT_GE(threads.size(), 5u) << "main, roscpp's, the reader, the loop, the spinner";
    for (const NodeThread& thread : threads) {
      SCOPED_TRACE(thread.name);
      EXPECT_EQ(thread.policy, SCHED_OTHER);
      const bool by_default = std::string(slice_param) == "_capture:=false";
      EXPECT_EQ(thread.slice_ns, by_default ? 100000u : kernel_slice);
    }
    node.signal(SIGTERM);
    EXPECT_TRUE(node.waitExit(10.0).has_value()) << "driver_node did not exit on SIGTERM";
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_base_node");
  ros::NodeHandle private_nh("~");

  std::string node_name = "driver_node";
  private_nh.getParam("node_name", node_name);
  if (!ros::param::get("/" + node_name + "/port", g_port) || g_port.empty()) {
    std::fprintf(stderr, "cannot read /%s/port from the parameter server\n", node_name.c_str());
    return 1;
  }
  g_driver_path = test_support::findDriverNode();

  RosSide ros_side(node_name);
  g_ros = &ros_side;
  const int result = RUN_ALL_TESTS();
  g_ros = nullptr;
  return result;
}
