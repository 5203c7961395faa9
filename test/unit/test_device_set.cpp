// The device set: one row per device, in kind order, and what walks it (the framer of a shared
// port, the diagnostics configuration in config/analyzers.yaml).
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "serial_robot_driver/device/device_set.h"

namespace serial_robot_driver::device {
namespace {

using protocol::FramerConfig;

void expectSameFamilies(const FramerConfig& a, const FramerConfig& b) {
  EXPECT_EQ(a.base, b.base);
  EXPECT_EQ(a.telemetry, b.telemetry);
  EXPECT_EQ(a.servo_response, b.servo_response);
  EXPECT_EQ(a.servo_request, b.servo_request);
  EXPECT_EQ(a.sync_write, b.sync_write);
  EXPECT_EQ(a.telemetry_servo_count, b.telemetry_servo_count);
}

TEST(DeviceSet, OneRowPerKindWithUniqueNames) {
  std::set<std::string> names;
  for (const DeviceDescription& device : deviceSet()) {
    EXPECT_EQ(&describe(device.kind), &device);
    EXPECT_TRUE(names.insert(device.name).second) << device.name;
    EXPECT_GE(device.family_count, 1u);
  }
  EXPECT_EQ(names, (std::set<std::string>{"base", "body", "servo_bus"}));
  EXPECT_EQ(deviceSet().front().kind, DeviceKind::kBase) << "the base starts and stops first";
}

TEST(DeviceSet, FramerOfEachCombinationAcceptsItsDevicesFamilies) {
  for (int mask = 1; mask < 8; ++mask) {
    std::vector<DeviceKind> devices;
    if (mask & 1) devices.push_back(DeviceKind::kBase);
    if (mask & 2) devices.push_back(DeviceKind::kBody);
    if (mask & 4) devices.push_back(DeviceKind::kServoBus);
    SCOPED_TRACE(mask);
    expectSameFamilies(framerFor(devices, 3),
                       FramerConfig::forDriver(mask & 1, mask & 2, mask & 4, 3));
  }
  // The servo bus also frames its own requests: the half-duplex echo.
  const FramerConfig bus = framerFor({DeviceKind::kServoBus}, 0);
  EXPECT_TRUE(bus.servo_response);
  EXPECT_TRUE(bus.servo_request);
  EXPECT_FALSE(bus.base);
}

TEST(DeviceSet, AnalyzersConfigurationGroupsEveryDevice) {
  std::ifstream file(std::string(SRD_SOURCE_DIR) + "/config/analyzers.yaml");
  ASSERT_TRUE(file.good());
  std::stringstream text;
  text << file.rdbuf();
  const std::string yaml = text.str();
  for (const DeviceDescription& device : deviceSet()) {
    const std::string block = std::string("      ") + device.name + ":\n";
    const std::size_t at = yaml.find(block);
    ASSERT_NE(at, std::string::npos) << "no analyzer for " << device.name;
    const std::string analyzer = yaml.substr(at, yaml.find("timeout", at) - at);
    EXPECT_NE(analyzer.find(std::string("path: ") + device.title + "\n"), std::string::npos)
        << analyzer;
    EXPECT_NE(analyzer.find(std::string("contains: ['driver_node: ") + device.name + "']"),
              std::string::npos)
        << analyzer;
  }
}

}  // namespace
}  // namespace serial_robot_driver::device
