// port_busy.test: a second driver_node on a port the first one holds is refused with "port busy"
// naming the holder's pid (log and diagnostics), and the first one's frames stay whole and in
// sequence meanwhile.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sys/wait.h>

#include <string>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "support/fake_device.h"
#include "support/framer_configs.h"
#include "support/process_support.h"
#include "support/ros_test_support.h"

namespace {

using test_support::FakeDevice;
using test_support::waitFor;
namespace protocol = serial_robot_driver::protocol;

TEST(PortBusy, SecondInstanceIsRefusedAndTheFirstKeepsDriving) {
  std::string port;
  ASSERT_TRUE(ros::param::get("/driver_node/port", port));
  FakeDevice base(port, test_support::driverFramer({"base"}));
  base.plug();
  ASSERT_TRUE(waitFor([&] { return base.frameCount() >= 5; }, 20.0))
      << "the first node sends nothing";
  const int first_pid = test_support::nodePid("/driver_node");
  ASSERT_GT(first_pid, 0);

  const std::string driver = test_support::findDriverNode();
  ASSERT_FALSE(driver.empty());
  test_support::ChildProcess second(
      driver,
      {"__name:=second_driver", "_port:=" + port, "_reconnect_interval:=0.2",
       "_base/battery_poll_rate:=0.0", "_body/enabled:=false", "_servo_bus/enabled:=false"});
  ASSERT_TRUE(second.started());
  const std::string expected =
      "port busy: " + port + " is locked by another process (pid " + std::to_string(first_pid);
  ASSERT_TRUE(waitFor([&] { return second.output().find(expected) != std::string::npos; }, 30.0))
      << second.output();

  ros::NodeHandle nh;
  test_support::DiagnosticsWatch diagnostics(nh, "second_driver");
  ASSERT_TRUE(waitFor([&] { return diagnostics.latest("port " + port).received > 0; }, 15.0));
  EXPECT_NE(diagnostics.latest("port " + port).message.find("port busy"), std::string::npos)
      << diagnostics.latest("port " + port).message;
  EXPECT_EQ(diagnostics.latest("port " + port).value("connected"), "False");

  // Meanwhile the first one's frames keep coming, whole and in sequence: nothing interleaved.
  const std::size_t before = base.frameCount();
  ASSERT_TRUE(waitFor([&] { return base.frameCount() >= before + 50; }, 20.0));
  EXPECT_TRUE(second.running()) << "the second instance waits for the port rather than exiting";
  const std::vector<FakeDevice::Frame> frames = base.frames();
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].bytes[3], static_cast<uint8_t>(frames[i - 1].bytes[3] + 1))
        << "frame " << i;
  }
  const protocol::FramerStats stats = base.framerStats();
  EXPECT_EQ(stats.checksum_errors, 0u);
  EXPECT_EQ(stats.bytes_skipped, 0u);

  second.signal(SIGTERM);
  const auto status = second.waitExit(15.0);
  ASSERT_TRUE(status.has_value());
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << second.output();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_port_busy");
  return RUN_ALL_TESTS();
}
