// The registered devices (cmake/devices.cmake, device/device_module.h) and what walks them: the
// framer of a shared port, the parameter table and the diagnostics configuration.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::core {
namespace {

using protocol::FrameFamily;
using protocol::FramerConfig;

std::set<std::string> familyNames(const FramerConfig& config) {
  std::set<std::string> names;
  for (std::size_t i = 0; i < config.family_count; ++i)
    names.insert(config.families[i].family.name);
  return names;
}

TEST(DeviceRegistry, UniqueNamesTheBaseFirst) {
  std::set<std::string> names;
  for (const DeviceModule* device : registeredDevices()) {
    EXPECT_TRUE(names.insert(device->name).second) << device->name;
    EXPECT_EQ(findDevice(device->name), device);
    EXPECT_FALSE(device->driver_frames.empty()) << device->name;
    EXPECT_NO_THROW(params::DriverParams().portParams(*device)) << device->name;
  }
  for (const char* name : {"base", "body", "servo_bus"}) EXPECT_EQ(names.count(name), 1u) << name;
  EXPECT_STREQ(registeredDevices().front()->name, "base") << "the base starts and stops first";
  EXPECT_EQ(findDevice("no_such_device"), nullptr);
}

TEST(DeviceRegistry, FindByNameGivesTheFirstOfThatNameOrNull) {
  struct Named {
    const char* name;
  };
  const Named a{"a"}, b{"b"}, a_again{"a"};
  EXPECT_EQ(findByName(std::vector<const Named*>{}, "a"), nullptr);
  const std::vector<const Named*> registry{&a, &b, &a_again};
  EXPECT_EQ(findByName(registry, "a"), &a);
  EXPECT_EQ(findByName(registry, "b"), &b);
  for (const char* other : {"", "A", "a ", "ab"}) {
    EXPECT_EQ(findByName(registry, other), nullptr) << "'" << other << "'";
  }
}

TEST(DeviceRegistry, FrameFamiliesHaveUniqueNames) {
  std::set<std::string> names;
  std::set<const char*> seen;
  for (const DeviceModule* device : registeredDevices()) {
    for (const auto* list : {&device->driver_frames, &device->simulator_frames}) {
      for (const FrameFamily& family : *list) {
        EXPECT_NE(family.probe, nullptr) << family.name;
        EXPECT_NE(family.decodes, nullptr) << family.name << ": the fuzzers decode what it frames";
        if (!seen.insert(family.name).second) continue;  // the same family twice (an echo)
        EXPECT_TRUE(names.insert(family.name).second) << family.name << " named twice";
      }
    }
  }
}

TEST(DeviceRegistry, FramerOfEachCombinationAcceptsItsDevicesFamilies) {
  const auto& all = registeredDevices();
  params::DriverParams params;
  params.section(devices::body::kBodySection).servo_ids = {1, 2, 3};
  for (std::size_t mask = 1; mask < (std::size_t{1} << all.size()); ++mask) {
    std::vector<const DeviceModule*> devices;
    std::set<std::string> expected;
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (!(mask & (std::size_t{1} << i))) continue;
      devices.push_back(all[i]);
      for (const FrameFamily& family : all[i]->driver_frames) expected.insert(family.name);
    }
    SCOPED_TRACE(mask);
    EXPECT_EQ(familyNames(framerFor(devices, params)), expected);
  }
  // The servo bus also frames its own requests: the half-duplex echo.
  const FramerConfig bus = framerFor({findDevice("servo_bus")}, params);
  EXPECT_EQ(familyNames(bus), (std::set<std::string>{"servo_response", "servo_request"}));
  // The body's telemetry is framed for its configured servo count.
  const FramerConfig body = framerFor({findDevice("body")}, params);
  EXPECT_EQ(body.expectedOf(devices::body::kTelemetryFrames), 3u);
}

TEST(DeviceRegistry, SimulatorFramerAcceptsWhatTheHostSends) {
  // The built-in devices' requests, and each other registered device's own (nothing else).
  std::set<std::string> expected{"base", "sync_write", "servo_request"};
  for (const DeviceModule* device : registeredDevices()) {
    const std::string name = device->name;
    if (name == "base" || name == "body" || name == "servo_bus") continue;
    for (const FrameFamily& family : device->simulator_frames) expected.insert(family.name);
  }
  EXPECT_EQ(familyNames(simulatorFramerFor(registeredDevices())), expected);
}

TEST(DeviceRegistry, EveryDeviceHasItsPortParameters) {
  std::set<std::string> keys;
  for (const params::ParamSpec& spec : params::parameterTable()) keys.insert(spec.key);
  for (const DeviceModule* device : registeredDevices()) {
    for (const char* key : {"/enabled", "/port", "/baud"}) {
      EXPECT_EQ(keys.count(device->name + std::string(key)), 1u) << device->name << key;
    }
  }
}

TEST(DeviceRegistry, AnalyzersConfigurationGroupsEveryDevice) {
  std::ifstream file(std::string(SRD_SOURCE_DIR) + "/config/analyzers.yaml");
  ASSERT_TRUE(file.good());
  std::stringstream text;
  text << file.rdbuf();
  const std::string yaml = text.str();
  for (const DeviceModule* device : registeredDevices()) {
    const std::string block = std::string("      ") + device->name + ":\n";
    const std::size_t at = yaml.find(block);
    ASSERT_NE(at, std::string::npos) << "no analyzer for " << device->name;
    const std::string analyzer = yaml.substr(at, yaml.find("timeout", at) - at);
    EXPECT_NE(analyzer.find(std::string("path: ") + device->title + "\n"), std::string::npos)
        << analyzer;
    EXPECT_NE(analyzer.find(std::string("contains: ['driver_node: ") + device->name + "']"),
              std::string::npos)
        << analyzer;
  }
}

}  // namespace
}  // namespace serial_robot_driver::core
