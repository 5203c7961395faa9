// The inputs the node refused, by source: counted from any thread, summed over the node's parts,
// and reported as keys of a status (the node's "e_stop" status).
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/input_refusals.h"

namespace {

using serial_robot_driver::core::addInputRefusals;
using serial_robot_driver::core::InputRefusals;
using serial_robot_driver::core::InputRefusalStats;
using serial_robot_driver::core::StatusLevel;
using serial_robot_driver::core::StatusReport;

TEST(InputRefusals, CountsEachSourceFromAnyThread) {
  InputRefusals refusals;
  std::vector<std::thread> senders;
  for (int t = 0; t < 4; ++t) {
    senders.emplace_back([&] {
      for (int i = 0; i < 1000; ++i) refusals.refused("joint_trajectory");
    });
  }
  for (std::thread& sender : senders) sender.join();
  refusals.refused("servo/move");
  refusals.failed("cmd_vel");
  const InputRefusalStats stats = refusals.stats();
  EXPECT_EQ(stats.refused.at("joint_trajectory"), 4000u);
  EXPECT_EQ(stats.refused.at("servo/move"), 1u);
  EXPECT_EQ(stats.errors.at("cmd_vel"), 1u);
  EXPECT_EQ(stats.errors.count("servo/move"), 0u);
}

TEST(InputRefusals, PartsAddUpAndTheStatusNamesEverySourceAndTheTotals) {
  InputRefusals body, node;
  body.refused("joint_commands");
  body.refused("joint_commands");
  node.refused("joint_trajectory");
  node.failed("follow_joint_trajectory");
  InputRefusalStats all = body.stats();
  all += node.stats();

  StatusReport status;
  status.summary(StatusLevel::kOk, "released");
  serial_robot_driver::core::addInputRefusals(all, status);
  EXPECT_EQ(*status.find("inputs refused: joint_commands"), "2");
  EXPECT_EQ(*status.find("inputs refused: joint_trajectory"), "1");
  EXPECT_EQ(*status.find("inputs refused"), "3");
  EXPECT_EQ(*status.find("callback errors: follow_joint_trajectory"), "1");
  EXPECT_EQ(*status.find("callback errors"), "1");
  EXPECT_EQ(status.level, StatusLevel::kOk) << "a refused input is the sender's mistake";

  StatusReport none;
  serial_robot_driver::core::addInputRefusals(InputRefusalStats{}, none);
  EXPECT_EQ(*none.find("inputs refused"), "0");
  EXPECT_EQ(*none.find("callback errors"), "0");
}

}  // namespace
