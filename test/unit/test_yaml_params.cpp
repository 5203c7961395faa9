// A parameter file read through the parameter table (params/yaml_param_source.h): what dds_driver
// --config reads is what the node reads from the parameter server, with the same checks.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/params/yaml_param_source.h"

namespace serial_robot_driver::params {
namespace {

/// A parameter file of its own for one test, removed at the end.
class ParamFile {
 public:
  explicit ParamFile(const std::string& text)
      : path_("/tmp/srd_yaml_params_" + std::to_string(getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".yaml") {
    std::ofstream(path_) << text;
  }
  ~ParamFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

TEST(YamlParams, TheShippedConfigIsValidAndHoldsNoUnknownKey) {
  std::vector<std::string> unknown{"stale"};
  const DriverParams params = loadParamsFile(SRD_SOURCE_DIR "/config/robot.yaml", &unknown);
  EXPECT_TRUE(unknown.empty()) << unknown.front();
  EXPECT_NO_THROW(params.validate());
}

TEST(YamlParams, NestedMapsAreTheGroupsKeysAndTfPrefixResolvesTheFrames) {
  const ParamFile file(
      "loop_rate: 25\n"
      "tf_prefix: robot1\n"
      "base: {wheel_diameter: 0.3, odom_frame: odom, wheel_diamter: 1}\n"
      "ros2:\n  enabled: true\n  domain_id: 7\n  peers: [127.0.0.1, robot2.local]\n");
  std::vector<std::string> unknown;
  const DriverParams params = loadParamsFile(file.path(), &unknown);
  EXPECT_EQ(params.loop_rate, 25.0) << "an integer is a number";
  const auto& base = params.section(devices::base::kBaseSection);
  EXPECT_EQ(base.controller.geometry.wheel_diameter, 0.3);
  EXPECT_EQ(base.odom_frame, "robot1/odom");
  EXPECT_TRUE(params.ros2.enabled);
  EXPECT_EQ(params.ros2.domain_id, 7);
  EXPECT_EQ(params.ros2.peers, (std::vector<std::string>{"127.0.0.1", "robot2.local"}));
  EXPECT_EQ(unknown, std::vector<std::string>{"base/wheel_diamter"});
  EXPECT_NO_THROW(params.validate());
}

TEST(YamlParams, AValueOfTheWrongTypeNamesItsParameter) {
  const ParamFile file("ros2: {domain_id: seven}\n");
  try {
    loadParamsFile(file.path(), nullptr);
    FAIL() << "a string loaded as the domain id";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "ros2/domain_id") << e.what();
  }
}

TEST(YamlParams, AValueOutOfRangeIsRefusedByTheNodesOwnCheck) {
  const ParamFile file("ros2: {domain_id: 233}\nbase: {max_wheel_speed: 0}\n");
  const DriverParams params = loadParamsFile(file.path(), nullptr);
  try {
    params.validate();
    FAIL() << "validate() accepted the file";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.name(), "ros2/domain_id") << e.what();
  }
}

TEST(YamlParams, AMissingOrMalformedFileIsAnErrorNotTheDefaults) {
  EXPECT_THROW(loadParamsFile("/nonexistent/robot.yaml", nullptr), std::runtime_error);
  const ParamFile list("- port: /dev/ttyUSB1\n");
  EXPECT_THROW(loadParamsFile(list.path(), nullptr), std::runtime_error);
}

}  // namespace
}  // namespace serial_robot_driver::params
