// driver_node's servo controller board (body_node.test): joint_commands become exact sync-write
// bytes, and the diagnostics count frames and rejected commands.
#include <gtest/gtest.h>

#include "support/body_node_fixture.h"

namespace {

using namespace body_node_test;  // NOLINT: the shared fixture

TEST_F(BodyNode, JointCommandsBecomeExactSyncWriteBytes) {
  ASSERT_TRUE(waitFor([&] { return board().joint_commands.getNumSubscribers() > 0; }, 30.0));
  board().drainInput();

  // Rejected commands write nothing: the first bytes on the wire belong to the valid one.
  board().joint_commands.publish(command({"hip", "elbow"}, {0.0, 0.0}));
  board().joint_commands.publish(command({"hip", "knee"}, {0.0}));
  board().joint_commands.publish(command({"hip", "knee"}, {0.0, std::nan("")}));
  // hip 0 rad -> 2048; knee pi/2 with direction -1 -> 2048 - 1024 = 1024 (docs/protocols.md 2a).
  board().joint_commands.publish(command({"hip", "knee"}, {0.0, M_PI / 2}));
  const Bytes& golden = golden::body::kSyncWrite2And3;
  EXPECT_EQ(board().read(golden.size()), golden);

  // Only knee, to -pi/2 -> 3072 = 00 0C; hip is sent again at 2048. CRC worked out by hand.
  board().joint_commands.publish(command({"knee"}, {-M_PI / 2}));
  const Bytes partial = {0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x83, 0x74, 0x00,
                         0x02, 0x00, 0x02, 0x00, 0x08, 0x03, 0x00, 0x0C, 0x4A, 0xE8};
  EXPECT_EQ(board().read(partial.size()), partial);
}

std::optional<std::string> value(const diagnostic_msgs::DiagnosticStatus& status,
                                 const std::string& key) {
  for (const auto& entry : status.values) {
    if (entry.key == key) return entry.value;
  }
  return std::nullopt;
}

TEST_F(BodyNode, DiagnosticsCountFramesAndRejectedCommands) {
  ros::NodeHandle nh;
  Inbox<diagnostic_msgs::DiagnosticArray> diagnostics;
  ros::Subscriber sub = subscribe(nh, "/diagnostics", &diagnostics);
  ASSERT_TRUE(waitFor([&] { return board().joint_commands.getNumSubscribers() > 0; }, 30.0));
  board().joint_commands.publish(command({"elbow"}, {0.0}));

  // The updater runs once a second; wait for a report that has seen both.
  std::optional<diagnostic_msgs::DiagnosticStatus> body;
  const auto counted = [&](const diagnostic_msgs::DiagnosticArray& array) {
    for (const auto& status : array.status) {
      if (status.name != "driver_node: body") continue;
      const auto frames = value(status, "frames decoded");
      const auto rejected = value(status, "commands rejected");
      if (frames && rejected && std::stoul(*frames) > 0 && std::stoul(*rejected) > 0) {
        body = status;
        return true;
      }
    }
    return false;
  };
  ASSERT_TRUE(diagnostics.waitFor(counted, 30.0)) << "no body status counting frames and rejects";
  EXPECT_EQ(body->hardware_id, value(*body, "port").value_or("(no port key)"));  // names the port
  EXPECT_FALSE(body->hardware_id.empty());
  EXPECT_EQ(value(*body, "connected"), std::optional<std::string>("True"));
  EXPECT_TRUE(value(*body, "decode errors").has_value());
  EXPECT_TRUE(value(*body, "commands sent").has_value());
  EXPECT_TRUE(value(*body, "Events since startup").has_value());  // the telemetry FrequencyStatus
}

// --- closed loop with robot_sim, and record.launch -----------------------------------------------

}  // namespace
