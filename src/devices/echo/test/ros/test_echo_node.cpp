// echo_node.test: echo/ping through driver_node to the echo device robot_sim hosts, and the
// device's diagnostic status counting the round trips.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <string>

#include "support/ros_test_support.h"
#include "support/test_helpers.h"

namespace {

using test_support::DiagnosticsWatch;

TEST(EchoNode, PingAnswersWithTheRoundTripAndDiagnosticsCountIt) {
  ros::NodeHandle nh;
  DiagnosticsWatch diagnostics(nh, "driver_node");
  ASSERT_TRUE(ros::service::waitForService("echo/ping", 30000));
  std_srvs::Trigger call;
  // The node retries its port until robot_sim's link exists: the first pings may find it down.
  ASSERT_TRUE(test_support::waitFor(
      [&] { return test_support::callService("echo/ping", call) && call.response.success; }, 20.0))
      << call.response.message;
  EXPECT_EQ(call.response.message.rfind("round trip ", 0), 0u) << call.response.message;
  EXPECT_NE(call.response.message.find(" ms"), std::string::npos) << call.response.message;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(test_support::callService("echo/ping", call));
    EXPECT_TRUE(call.response.success) << call.response.message;
  }

  const auto status = diagnostics.waitFor(
      "echo", 0, [](const DiagnosticsWatch::Status& s) { return s.number("round trips") >= 5; },
      [] { return ros::ok(); }, 20.0);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(status->level, diagnostic_msgs::DiagnosticStatus::OK) << status->message;
  EXPECT_EQ(status->message, "answering");
  EXPECT_EQ(status->number("mismatched answers"), 0u);
  EXPECT_EQ(status->value("port"), "/tmp/srd_test_echo");
  EXPECT_FALSE(status->value("last round trip ms").empty());
  // The base shares the port: it is still there, untouched by the echo device.
  EXPECT_FALSE(diagnostics.latest("base").message.empty());
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_echo_node");
  return RUN_ALL_TESTS();
}
