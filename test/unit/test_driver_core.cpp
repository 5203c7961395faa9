// The driver's core without a front end (device/driver_core.h): the devices built on their ports
// in the registered order, started after the ports and shut down in that order before them, the
// e-stop and the capabilities handed to every device, one MotionQuery over all of them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <memory>
#include <string>
#include <vector>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::core {
namespace {

/// A device that writes what the core asks of it into a shared log.
class LoggingDevice : public Device {
 public:
  LoggingDevice(std::string name, std::vector<std::string>& log)
      : name_(std::move(name)), log_(log) {}

  void start() override { log_.push_back("start " + name_); }
  void shutdown() override { log_.push_back("shutdown " + name_); }
  StatusReport status() override { return {}; }
  std::vector<NamedStatus> extraStatuses() override {
    return {{name_ + " extra", [] { return StatusReport{}; }}};
  }
  void attachEStop(EStop& e_stop) override {
    e_stop_ = &e_stop;
    log_.push_back("e_stop " + name_);
  }
  void offerCapabilities(Capabilities&) override { log_.push_back("offer " + name_); }
  void useCapabilities(const Capabilities& capabilities) override {
    motion_ = capabilities.find<MotionQuery>();
    log_.push_back("use " + name_);
  }
  std::string motionInForce() const override { return moving; }

  std::string moving;
  EStop* e_stop_ = nullptr;
  MotionQuery* motion_ = nullptr;

 private:
  std::string name_;
  std::vector<std::string>& log_;
};

class DriverCoreTest : public ::testing::Test {
 protected:
  DriverCoreTest() {
    // Paths that never open: the links keep retrying in the background, which is all these need.
    const std::string prefix = "/tmp/srd_core_test_" + std::to_string(::getpid());
    params.port = prefix + "_shared";
    params.portParams(*findDevice("servo_bus")).port = prefix + "_bus";
  }

  std::unique_ptr<DriverCore> makeCore() {
    return std::make_unique<DriverCore>(
        params, [this](const DeviceModule& module, SerialLink& link) {
          log.push_back(std::string("make ") + module.name + " on " + link.options().path);
          auto device = std::make_unique<LoggingDevice>(module.name, log);
          made.push_back(device.get());
          return device;
        });
  }

  params::DriverParams params;
  std::vector<std::string> log;
  std::vector<LoggingDevice*> made;
};

TEST_F(DriverCoreTest, BuildsEveryEnabledDeviceOnItsPortInTheRegisteredOrderThenWiresThem) {
  auto core = makeCore();
  const std::vector<std::string> expected{
      "make base on " + params.port,
      "make body on " + params.port,
      "make servo_bus on " + params.portOf(*findDevice("servo_bus")),
      "offer base",
      "offer body",
      "offer servo_bus",  // every offer before any ask
      "use base",
      "use body",
      "use servo_bus",
      "e_stop base",
      "e_stop body",
      "e_stop servo_bus"};
  EXPECT_EQ(log, expected);
  EXPECT_EQ(core->ports().size(), 2u) << "base and body share a port, the bus has its own";
  EXPECT_EQ(core->deviceNames(), (std::vector<std::string>{"base", "body", "servo_bus"}));
  for (LoggingDevice* device : made) {
    EXPECT_EQ(device->e_stop_, &core->eStop());
    EXPECT_EQ(device->motion_, &core->motion());
  }
  EXPECT_EQ(core->trajectories(), nullptr) << "no device offered joints";
  const std::string summary = core->startupSummary();
  EXPECT_NE(summary.find(params.port + " (115200 baud: base, body)"), std::string::npos) << summary;
}

TEST_F(DriverCoreTest, TheStartupSummaryNamesNoBaudForAPortOverTcp) {
  params.port = "tcp://127.0.0.1:4001";
  const std::string summary = makeCore()->startupSummary();
  EXPECT_NE(summary.find("tcp://127.0.0.1:4001 (TCP: base, body)"), std::string::npos) << summary;
  EXPECT_NE(summary.find("_bus (115200 baud: servo_bus)"), std::string::npos) << summary;
}

TEST_F(DriverCoreTest, StartsTheDevicesAfterThePortsAndShutsThemDownOnceInTheSameOrder) {
  auto core = makeCore();
  log.clear();
  core->start();
  core->shutdown();
  core->shutdown();
  const std::vector<std::string> expected{"start base",    "start body",    "start servo_bus",
                                          "shutdown base", "shutdown body", "shutdown servo_bus"};
  EXPECT_EQ(log, expected);
  core.reset();
  EXPECT_EQ(log.size(), expected.size()) << "destroying a shut-down core shuts nothing down again";
}

TEST_F(DriverCoreTest, TheMotionQueryNamesTheFirstDeviceThatMoves) {
  auto core = makeCore();
  EXPECT_EQ(core->motion().motionInForce(), "");
  made[2]->moving = "servo 3 moving";
  EXPECT_EQ(core->motion().motionInForce(), "servo_bus: servo 3 moving");
  made[1]->moving = "joint command";
  EXPECT_EQ(core->motion().motionInForce(), "body: joint command");
}

TEST_F(DriverCoreTest, AnEStopEngagedAtStartUpHoldsBeforeAnythingStarts) {
  EXPECT_FALSE(makeCore()->eStop().engaged());
  params.e_stop.start_engaged = true;
  EXPECT_TRUE(makeCore()->eStop().engaged());
}

TEST_F(DriverCoreTest, TheEStopStatusCountsTheDevicesRefusalsWithTheFrontEndsOwn) {
  auto core = makeCore();
  made[0]->inputRefusals().refused("cmd_vel");
  made[2]->inputRefusals().refused("servo/move");
  core->inputRefusals().refused("e_stop");
  core->inputRefusals().refused("e_stop");
  const StatusReport report = core->eStopStatus();
  auto value = [&report](const std::string& key) {
    for (const auto& [k, v] : report.values) {
      if (k == key) return v;
    }
    return std::string("(absent)");
  };
  EXPECT_EQ(value("inputs refused: cmd_vel"), "1");
  EXPECT_EQ(value("inputs refused: servo/move"), "1");
  EXPECT_EQ(value("inputs refused: e_stop"), "2");
  EXPECT_EQ(value("inputs refused"), "4");
}

TEST_F(DriverCoreTest, EveryFrontEndReportsThePortsTheDevicesWithTheirOwnThenTheEStop) {
  auto core = makeCore();
  std::vector<Device::NamedStatus> sources = core->statusSources();
  std::vector<std::string> names;
  for (const auto& source : sources) names.push_back(source.name);
  const std::string prefix = "port /tmp/srd_core_test_" + std::to_string(::getpid());
  const std::vector<std::string> expected{
      prefix + "_bus", prefix + "_shared", "base",  "base extra", "body", "body extra",
      "servo_bus",     "servo_bus extra",  "e_stop"};
  EXPECT_EQ(names, expected);
}

TEST_F(DriverCoreTest, EveryFrontEndsEStopStatusCountsWhatAnyFrontEndRefused) {
  auto core = makeCore();
  // Two front ends (a ROS 1 node and a ROS 2 graph in one process), each refusing one input.
  const std::vector<Device::NamedStatus> ros1 = core->statusSources();
  const std::vector<Device::NamedStatus> ros2 = core->statusSources();
  core->inputRefusals().refused("joint_trajectory");  // the ROS 2 graph's
  core->inputRefusals().refused("e_stop");            // the ROS 1 node's
  const StatusReport seen_by_ros1 = ros1.back().report();
  EXPECT_EQ(seen_by_ros1.values, ros2.back().report().values) << "one e-stop, one count";
  bool counted = false;
  for (const auto& [key, value] : seen_by_ros1.values)
    counted |= key == "inputs refused" && value == "2";
  EXPECT_TRUE(counted) << "asked when the status is, not when the sources were made";
}

}  // namespace
}  // namespace serial_robot_driver::core
