// config/analyzers.yaml groups driver_node's statuses (analyzers.test runs the driver on the
// simulator): every group of the file (Ports, Base, Body, Servo bus) must hold at least one of the
// driver's statuses, and none of them may fall through to the aggregator's "Other" group. The
// aggregator is diagnostic_aggregator's own class, fed the file from this node's private namespace.
#include <diagnostic_aggregator/aggregator.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <chrono>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "support/ros_test_support.h"

namespace {

const std::string kRoot = "/Serial robot";
const std::vector<std::string> kGroups = {"Ports", "Base", "Body", "Servo bus"};

// The newest /diagnostics_agg: status names and levels.
class AggregatedNames {
 public:
  explicit AggregatedNames(ros::NodeHandle& nh)
      : sub_(nh.subscribe("/diagnostics_agg", 10, &AggregatedNames::onArray, this)) {}

  std::vector<std::string> names() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return names_;
  }

 private:
  void onArray(const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
    std::lock_guard<std::mutex> lock(mutex_);
    names_.clear();
    for (const auto& status : array->status) names_.push_back(status.name);
  }

  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::vector<std::string> names_;
};

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

// Children per group of the file, and the driver's statuses that landed in "Other".
struct Grouping {
  std::map<std::string, int> children;
  std::vector<std::string> driver_in_other;
};

Grouping group(const std::vector<std::string>& names) {
  Grouping grouping;
  for (const auto& name : names) {
    for (const auto& g : kGroups)
      if (startsWith(name, kRoot + "/" + g + "/")) ++grouping.children[g];
    if (startsWith(name, "/Other/") && name.find("driver_node") != std::string::npos)
      grouping.driver_in_other.push_back(name);
  }
  return grouping;
}

TEST(Analyzers, GroupEveryDriverStatus) {
  ros::NodeHandle nh;
  // Both live as long as the process: their callbacks run on the spinner thread, and roscpp cannot
  // wait for one already running, so destroying them at the end of the test could pull a mutex
  // from under it (seen once: boost::lock_error, "mutex lock failed").
  auto& aggregator = *new diagnostic_aggregator::Aggregator();  // reads ~analyzers
  auto& aggregated = *new AggregatedNames(nh);

  // Until every group has a child (the sim connects, then the driver reports about once a second).
  Grouping grouping;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  bool all_groups = false;
  while (ros::ok() && !all_groups && std::chrono::steady_clock::now() < deadline) {
    aggregator.publishData();
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    grouping = group(aggregated.names());
    all_groups = true;
    for (const auto& g : kGroups) all_groups = all_groups && grouping.children[g] > 0;
  }
  for (const auto& g : kGroups)
    EXPECT_GT(grouping.children[g], 0) << "no status in " << kRoot << "/" << g;
  EXPECT_TRUE(grouping.driver_in_other.empty())
      << "ungrouped driver status, e.g. " << grouping.driver_in_other.front();
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_analyzers", 1);
  return RUN_ALL_TESTS();
}
