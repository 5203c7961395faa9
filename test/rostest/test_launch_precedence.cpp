// driver.launch's parameter precedence (launch_precedence.test includes it twice with the same
// parameter file, which sets port and baud):
//  - /from_file: no port:= / baud:= given, so the file's values must reach the node;
//  - /from_args: port:= and baud:= given, so they must override the file's.
// Checked twice: on the parameter server, and in what each running node reports in /diagnostics
// (a status of the node must name the port it uses, and none may name the other one), so the test
// also fails if the node read its port from anywhere else.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <chrono>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <utility>

#include "support/ros_test_support.h"

namespace {

std::string requiredParam(const std::string& name) {
  std::string value;
  if (!ros::param::get(name, value)) ADD_FAILURE() << "missing test parameter " << name;
  return value;
}

int requiredIntParam(const std::string& name) {
  int value = 0;
  if (!ros::param::get(name, value)) ADD_FAILURE() << "missing test parameter " << name;
  return value;
}

// Every port path each driver names in its statuses, keyed by the driver's namespace. A status
// belongs to a driver when its name starts with "<ns>/" (diagnostic_updater prefixes the node's
// name); a path counts when it appears in the status name or in one of its values.
class PortsInDiagnostics {
 public:
  PortsInDiagnostics(ros::NodeHandle& nh, std::set<std::string> candidate_paths)
      : candidates_(std::move(candidate_paths)) {
    sub_ = nh.subscribe("/diagnostics", 100, &PortsInDiagnostics::onDiagnostics, this);
  }
  // onDiagnostics runs on the spinner thread until the subscription ends, and the members it uses
  // die before sub_ would: shutdown() waits for a running callback.
  ~PortsInDiagnostics() { sub_.shutdown(); }
  PortsInDiagnostics(const PortsInDiagnostics&) = delete;
  PortsInDiagnostics& operator=(const PortsInDiagnostics&) = delete;

  std::set<std::string> mentionedBy(const std::string& ns) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::set<std::string> paths;
    for (const auto& [key, path] : mentions_)
      if (key == ns) paths.insert(path);
    return paths;
  }

 private:
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& array) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& status : array->status) {
      const std::string name = status.name.rfind('/', 0) == 0 ? status.name.substr(1) : status.name;
      const auto slash = name.find('/');
      if (slash == std::string::npos) continue;
      const std::string ns = name.substr(0, slash);
      for (const auto& path : candidates_) {
        bool mentioned = name.find(path) != std::string::npos;
        for (const auto& value : status.values) mentioned = mentioned || value.value == path;
        if (mentioned) mentions_.insert({ns, path});
      }
    }
  }

  const std::set<std::string> candidates_;
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::set<std::pair<std::string, std::string>> mentions_;
};

bool waitUntil(const std::function<bool()>& done, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (ros::ok() && std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return done();
}

class LaunchPrecedence : public testing::Test {
 protected:
  const std::string file_port_ = requiredParam("~file_port");
  const int file_baud_ = requiredIntParam("~file_baud");
  const std::string arg_port_ = requiredParam("~arg_port");
  const int arg_baud_ = requiredIntParam("~arg_baud");
};

TEST_F(LaunchPrecedence, FileValuesWinWithoutArgs) {
  std::string port;
  int baud = 0;
  ASSERT_TRUE(ros::param::get("/from_file/driver_node/port", port));
  ASSERT_TRUE(ros::param::get("/from_file/driver_node/baud", baud));
  EXPECT_EQ(port, file_port_);
  EXPECT_EQ(baud, file_baud_);
}

TEST_F(LaunchPrecedence, ExplicitArgsOverrideTheFile) {
  std::string port;
  int baud = 0;
  ASSERT_TRUE(ros::param::get("/from_args/driver_node/port", port));
  ASSERT_TRUE(ros::param::get("/from_args/driver_node/baud", baud));
  EXPECT_EQ(port, arg_port_);
  EXPECT_EQ(baud, arg_baud_);
}

TEST_F(LaunchPrecedence, EachRunningDriverUsesItsPort) {
  ros::NodeHandle nh;
  PortsInDiagnostics diagnostics(nh, {file_port_, arg_port_, "/dev/ttyUSB0"});
  // The node publishes diagnostics about once a second; allow for a slow start on a busy machine.
  const bool both_reported = waitUntil(
      [&] {
        return diagnostics.mentionedBy("from_file").count(file_port_) > 0 &&
               diagnostics.mentionedBy("from_args").count(arg_port_) > 0;
      },
      60.0);
  ASSERT_TRUE(both_reported) << "no /diagnostics status of a driver named its expected port";
  // A few more publications, in case a node also reported another port.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  EXPECT_EQ(diagnostics.mentionedBy("from_file"), std::set<std::string>{file_port_});
  EXPECT_EQ(diagnostics.mentionedBy("from_args"), std::set<std::string>{arg_port_});
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  test_support::RosTestNode node(argc, argv, "test_launch_precedence", 1);
  return RUN_ALL_TESTS();
}
