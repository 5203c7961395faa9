// robot_description's command line (description/robot_description_command.h): the arguments, the
// texts and the exit statuses, without running the executable.
#include <gtest/gtest.h>
#include <unistd.h>
#include <urdf/model.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "serial_robot_driver/description/robot_description_command.h"

namespace serial_robot_driver::description {
namespace {

const std::string kDefaultConfig = std::string(SRD_SOURCE_DIR) + "/config/robot.yaml";

// Written by hand: the mounts of the registered parts (the body's IMU) in the usage text.
const std::string kUsage =
    "usage: robot_description CONFIG.yaml [--imu-xyz \"X Y Z\"] [--imu-rpy \"R P Y\"] "
    "[--name NAME]\n"
    "  prints the URDF of the robot CONFIG.yaml configures (driver_node's parameter file);\n"
    "  --imu-xyz (m) and --imu-rpy (rad) place imu_link on the base (default 0 0 0).\n";

struct Outcome {
  int status;
  std::string out, err;
};

Outcome run(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int status = runRobotDescription(args, out, err);
  return {status, out.str(), err.str()};
}

TEST(RobotDescriptionCommand, HelpPrintsTheUsageWithEveryMount) {
  EXPECT_EQ(descriptionUsage(), kUsage);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--help"}, {"-h"}, {kDefaultConfig, "--name", "r", "-h", "x y"}}) {
    const Outcome outcome = run(args);
    EXPECT_EQ(outcome.status, 0) << args.size();
    EXPECT_EQ(outcome.out, kUsage);
    EXPECT_EQ(outcome.err, "");
  }
}

TEST(RobotDescriptionCommand, WithoutAConfigTheUsageGoesToStderr) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{}, {"--name", "robot"}, {"--imu-xyz", "1 2 3"}}) {
    const Outcome outcome = run(args);
    EXPECT_EQ(outcome.status, 2) << args.size();
    EXPECT_EQ(outcome.out, "");
    EXPECT_EQ(outcome.err, kUsage);
  }
}

TEST(RobotDescriptionCommand, AMountTakesExactlyThreeNumbers) {
  for (const std::string& bad :
       std::vector<std::string>{"1 2", "1 2 3 4", "a b c", "", "1 2 3x", "nan 0 0"}) {
    const Outcome outcome = run({kDefaultConfig, "--imu-rpy", bad});
    EXPECT_EQ(outcome.status, 2) << bad;
    EXPECT_EQ(outcome.out, "");
    EXPECT_EQ(outcome.err, "robot_description: --imu-rpy takes three numbers, got '" + bad + "'\n");
  }
  const ParsedDescriptionArguments parsed =
      parseDescriptionArguments({"--imu-xyz", " -1e-3\t+2  0 ", kDefaultConfig});
  ASSERT_TRUE(parsed.request) << parsed.error;
  EXPECT_EQ(parsed.request->mounts.at("imu").xyz, (std::array<double, 3>{-1e-3, 2, 0}));
  EXPECT_EQ(parsed.request->mounts.at("imu").rpy, (std::array<double, 3>{0, 0, 0}));
}

TEST(RobotDescriptionCommand, AnArgumentOutOfPlaceIsRefusedWithTheUsage) {
  for (const std::vector<std::string>& args : {
           std::vector<std::string>{kDefaultConfig, "other.yaml"},  // a second file
           {kDefaultConfig, "--bogus", "1"},                        // no such option
           {kDefaultConfig, "--base-xyz", "1 2 3"},                 // no such mount
           {kDefaultConfig, "--name"},                              // without its value
           {kDefaultConfig, "--imu-xyz"},
           {"--name"},
       }) {
    const Outcome outcome = run(args);
    EXPECT_EQ(outcome.status, 2) << args.back();
    EXPECT_EQ(outcome.out, "");
    EXPECT_EQ(outcome.err, "robot_description: unexpected argument '" +
                               args[args.size() > 1 ? 1 : 0] + "'\n" + kUsage);
  }
}

TEST(RobotDescriptionCommand, OptionsTakeTheNextArgumentWhateverItIs) {
  const ParsedDescriptionArguments parsed =
      parseDescriptionArguments({"--name", "--help", "-config.yaml", "--name", "last"});
  ASSERT_TRUE(parsed.request) << parsed.error;
  EXPECT_FALSE(parsed.help);
  EXPECT_EQ(parsed.request->config, "-config.yaml") << "one dash: a file";
  EXPECT_EQ(parsed.request->name, "last") << "the last --name";
  EXPECT_TRUE(parsed.request->mounts.empty()) << "no mount given";
  EXPECT_EQ(parseDescriptionArguments({"c.yaml"}).request->name, "serial_robot");
}

TEST(RobotDescriptionCommand, TheNameAndTheMountsReachTheUrdf) {
  const Outcome outcome =
      run({"--imu-xyz", "0.1 0 0.2", kDefaultConfig, "--name", "rover", "--imu-rpy", "0 0 1.5"});
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  EXPECT_EQ(outcome.err, "");
  urdf::Model model;
  ASSERT_TRUE(model.initString(outcome.out));
  EXPECT_EQ(model.getName(), "rover");
  const auto imu = model.getJoint("imu_link_joint");
  ASSERT_TRUE(imu);
  EXPECT_DOUBLE_EQ(imu->parent_to_joint_origin_transform.position.x, 0.1);
  EXPECT_DOUBLE_EQ(imu->parent_to_joint_origin_transform.position.z, 0.2);
  double roll, pitch, yaw;
  imu->parent_to_joint_origin_transform.rotation.getRPY(roll, pitch, yaw);
  EXPECT_NEAR(yaw, 1.5, 1e-9);
}

TEST(RobotDescriptionCommand, AFileThatCannotBeUsedFailsNamingIt) {
  Outcome outcome = run({"/nonexistent.yaml"});
  EXPECT_EQ(outcome.status, 1);
  EXPECT_EQ(outcome.out, "");
  EXPECT_EQ(outcome.err.rfind("robot_description: /nonexistent.yaml: ", 0), 0u) << outcome.err;
  EXPECT_EQ(outcome.err.back(), '\n');
  // Read, but refused by the driver's own checks.
  const std::string file = "/tmp/srd_description_command_" + std::to_string(getpid()) + ".yaml";
  { std::ofstream(file) << "base: {wheel_diameter: -0.1}\n"; }
  outcome = run({file});
  std::remove(file.c_str());
  EXPECT_EQ(outcome.status, 1);
  EXPECT_EQ(outcome.out, "");
  EXPECT_EQ(outcome.err.rfind("robot_description: " + file + ": ", 0), 0u) << outcome.err;
  EXPECT_NE(outcome.err.find("base/wheel_diameter"), std::string::npos) << outcome.err;
}

}  // namespace
}  // namespace serial_robot_driver::description
