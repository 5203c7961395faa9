// The robot description: the executable's URDF passes check_urdf for the default parameter file
// and for another robot's; links, joints, placements and limits follow the parameters.
#include <gtest/gtest.h>
#include <urdf/model.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "serial_robot_driver/description/robot_description.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"

namespace serial_robot_driver::description {
namespace {

const std::string kDefaultConfig = std::string(SRD_SOURCE_DIR) + "/config/robot.yaml";
const std::string kOtherConfig =
    std::string(SRD_SOURCE_DIR) + "/test/config/description_other.yaml";

struct CommandResult {
  int status;
  std::string output;
};

CommandResult run(const std::string& command) {
  CommandResult result{-1, ""};
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  while (std::size_t n = fread(buffer, 1, sizeof buffer, pipe)) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// The executable's URDF for `config` written to a file, and check_urdf's verdict on it.
std::string generatedUrdf(const std::string& config, const std::string& extra_args = "") {
  const CommandResult generated =
      run(std::string(SRD_ROBOT_DESCRIPTION) + " '" + config + "' " + extra_args);
  EXPECT_EQ(generated.status, 0) << generated.output;
  return generated.output;
}

void expectCheckUrdfPasses(const std::string& urdf, const std::string& file) {
  { std::ofstream(file) << urdf; }
  const CommandResult check = run("check_urdf '" + file + "'");
  EXPECT_EQ(check.status, 0) << check.output;
  EXPECT_NE(check.output.find("Successfully Parsed XML"), std::string::npos) << check.output;
  std::remove(file.c_str());
}

urdf::Model parse(const std::string& urdf) {
  urdf::Model model;
  EXPECT_TRUE(model.initString(urdf));
  return model;
}

constexpr double kTick = 2 * M_PI / 4096;

TEST(RobotDescription, DefaultConfigPassesCheckUrdfAndFollowsTheGeometry) {
  const std::string urdf =
      generatedUrdf(kDefaultConfig, "--imu-xyz '0.1 0 0.2' --imu-rpy '0 0 1.5'");
  expectCheckUrdfPasses(urdf, "/tmp/srd_description_default_" + std::to_string(getpid()) + ".urdf");
  const urdf::Model model = parse(urdf);
  ASSERT_TRUE(model.getRoot());
  EXPECT_EQ(model.getRoot()->name, "base_link");

  for (const auto& [name, side] :
       {std::pair{"left_wheel_joint", 1.0}, {"right_wheel_joint", -1.0}}) {
    const auto joint = model.getJoint(name);
    ASSERT_TRUE(joint) << name;
    EXPECT_EQ(joint->type, urdf::Joint::CONTINUOUS);
    EXPECT_EQ(joint->parent_link_name, "base_link");
    EXPECT_DOUBLE_EQ(joint->parent_to_joint_origin_transform.position.y, side * 0.40 / 2);
    EXPECT_DOUBLE_EQ(joint->parent_to_joint_origin_transform.position.z, 0.25 / 2);
    EXPECT_DOUBLE_EQ(joint->axis.y, 1.0);
    const auto wheel = model.getLink(joint->child_link_name);
    ASSERT_TRUE(wheel && wheel->visual && wheel->visual->geometry);
    const auto* cylinder = dynamic_cast<const urdf::Cylinder*>(wheel->visual->geometry.get());
    ASSERT_TRUE(cylinder);
    EXPECT_DOUBLE_EQ(cylinder->radius, 0.25 / 2);
  }

  const auto imu = model.getJoint("imu_link_joint");
  ASSERT_TRUE(imu);
  EXPECT_EQ(imu->type, urdf::Joint::FIXED);
  EXPECT_EQ(imu->child_link_name, "imu_link");
  EXPECT_DOUBLE_EQ(imu->parent_to_joint_origin_transform.position.x, 0.1);
  EXPECT_DOUBLE_EQ(imu->parent_to_joint_origin_transform.position.z, 0.2);
  double roll, pitch, yaw;
  imu->parent_to_joint_origin_transform.rotation.getRPY(roll, pitch, yaw);
  EXPECT_NEAR(yaw, 1.5, 1e-9);

  // Ticks 0..4095 around the zero 2048, direction 1.
  for (const char* name : {"joint_1", "joint_2"}) {
    const auto joint = model.getJoint(name);
    ASSERT_TRUE(joint && joint->limits) << name;
    EXPECT_EQ(joint->type, urdf::Joint::REVOLUTE);
    EXPECT_NEAR(joint->limits->lower, -2048 * kTick, 1e-8);
    EXPECT_NEAR(joint->limits->upper, 2047 * kTick, 1e-8);
  }
  // Every joint is one of these: no bus-servo joints in the default file.
  EXPECT_EQ(model.joints_.size(), 5u);
}

TEST(RobotDescription, OtherNamesGeometryZerosAndDirectionsAreFollowed) {
  const std::string urdf = generatedUrdf(kOtherConfig);
  expectCheckUrdfPasses(urdf, "/tmp/srd_description_other_" + std::to_string(getpid()) + ".urdf");
  const urdf::Model model = parse(urdf);
  ASSERT_TRUE(model.getRoot());
  EXPECT_EQ(model.getRoot()->name, "chassis");
  const auto left = model.getJoint("wheel_l");
  ASSERT_TRUE(left);
  EXPECT_DOUBLE_EQ(left->parent_to_joint_origin_transform.position.y, 0.15);
  EXPECT_DOUBLE_EQ(left->parent_to_joint_origin_transform.position.z, 0.05);
  ASSERT_TRUE(model.getJoint("wheel_r"));
  EXPECT_FALSE(model.getJoint("left_wheel_joint"));
  EXPECT_TRUE(model.getLink("imu"));
  EXPECT_FALSE(model.getLink("imu_link"));

  const auto neck = model.getJoint("neck_joint");  // zero 0, direction 1: 0 .. 4095 ticks
  ASSERT_TRUE(neck && neck->limits);
  EXPECT_EQ(neck->child_link_name, "neck_link");
  EXPECT_NEAR(neck->limits->lower, 0.0, 1e-8);
  EXPECT_NEAR(neck->limits->upper, 4095 * kTick, 1e-8);
  const auto tail = model.getJoint("tail");  // zero 1024, direction -1
  ASSERT_TRUE(tail && tail->limits);
  EXPECT_NEAR(tail->limits->lower, -(4095 - 1024) * kTick, 1e-8);
  EXPECT_NEAR(tail->limits->upper, 1024 * kTick, 1e-8);
  const auto gripper = model.getJoint("gripper");  // -180..180 deg, zero 90, direction -1
  ASSERT_TRUE(gripper && gripper->limits);
  EXPECT_EQ(gripper->type, urdf::Joint::REVOLUTE);
  EXPECT_NEAR(gripper->limits->lower, -M_PI / 2, 1e-8);
  EXPECT_NEAR(gripper->limits->upper, 3 * M_PI / 2, 1e-8);
}

TEST(RobotDescription, BadFilesAreRefusedNamingTheParameter) {
  const std::string file = "/tmp/srd_description_bad_" + std::to_string(getpid()) + ".yaml";
  const auto refusal = [&file](const std::string& yaml) {
    { std::ofstream(file) << yaml; }
    const CommandResult result = run(std::string(SRD_ROBOT_DESCRIPTION) + " '" + file + "'");
    EXPECT_NE(result.status, 0) << yaml;
    return result.output;
  };
  EXPECT_NE(refusal("base: {wheel_diameter: -0.1}\n").find("base/wheel_diameter"),
            std::string::npos);
  EXPECT_NE(refusal("base: {wheel_diameter: wide}\n").find("base/wheel_diameter"),
            std::string::npos);
  EXPECT_NE(refusal("servo_bus: {joint_ids: [5], joint_names: [joint_1]}\n")
                .find("servo_bus/joint_names"),
            std::string::npos)
      << "a bus joint named like a body joint";
  EXPECT_NE(
      refusal("servo_bus: {joint_ids: [5, 6], joint_names: [a]}\n").find("servo_bus/joint_names"),
      std::string::npos);
  EXPECT_NE(
      refusal("base: {left_wheel_joint: w, right_wheel_joint: w}\n").find("base/right_wheel_joint"),
      std::string::npos);
  std::remove(file.c_str());
  EXPECT_NE(run(std::string(SRD_ROBOT_DESCRIPTION) + " /nonexistent.yaml").status, 0);
}

TEST(YamlParamSource, ReadsTheDriversParametersWithTheirDefaults) {
  const YamlParamSource source(kOtherConfig);
  std::vector<std::string> unknown;
  const DriverParams params = loadParams(source, &unknown);
  EXPECT_DOUBLE_EQ(params.section(devices::base::kBaseSection).controller.geometry.wheel_diameter,
                   0.1);
  EXPECT_EQ(params.section(devices::base::kBaseSection).left_wheel_joint, "wheel_l");
  EXPECT_EQ(params.section(devices::body::kBodySection).servo_ids, (std::vector<int>{3, 4}));
  EXPECT_EQ(params.section(devices::body::kBodySection).directions, (std::vector<int>{1, -1}));
  EXPECT_EQ(params.loop_rate, DriverParams().loop_rate) << "absent: the driver's default";
  EXPECT_TRUE(params.section(devices::base::kBaseSection).publish_tf);
  EXPECT_EQ(params.section(devices::servo_bus::kServoBusSection).joint_ids, (std::vector<int>{5}));
  EXPECT_EQ(params.section(devices::servo_bus::kServoBusSection).joint_names,
            (std::vector<std::string>{"gripper"}));
  EXPECT_EQ(params.section(devices::servo_bus::kServoBusSection).joint_zero_deg,
            (std::vector<double>{90.0}));
  EXPECT_EQ(params.section(devices::servo_bus::kServoBusSection).joint_directions,
            (std::vector<int>{-1}));
}

TEST(RobotDescription, LinkNamesDropALeadingSlash) {
  EXPECT_EQ(linkName("/base_link"), "base_link");
  EXPECT_EQ(linkName("base_link"), "base_link");
}

}  // namespace
}  // namespace serial_robot_driver::description
