// robot_sim's command line: flags, roslaunch's extra arguments, errors and --help.
#include <gtest/gtest.h>

#include "support/sim_host.h"

namespace serial_robot_driver::sim {
namespace {

using namespace sim_test;  // NOLINT: the shared fixture

// --- command line ----------------------------------------------------------------------------

CommandLine parse(std::vector<const char*> args) {
  args.insert(args.begin(), "robot_sim");
  return parseCommandLine(static_cast<int>(args.size()), args.data());
}

TEST(RobotSimCommandLine, ParsesFlagsAndIgnoresRoslaunchArguments) {
  CommandLine line =
      parse({"--servo-ids", "3,4,5", "--foot-alternate", "__name:=sim", "__log:=/tmp/x.log",
             "--seed=9", "--corrupt-rate", "0.5", "--base-link", "/tmp/b", "--no-servo-bus",
             "--battery", "40", "--telemetry-rate", "0", "--offline-ids", "7"});
  ASSERT_TRUE(line.error.empty()) << line.error;
  EXPECT_FALSE(line.help);
  EXPECT_EQ(devices::body::sim::bodyConfig(line.options).servo_ids,
            (std::vector<uint8_t>{3, 4, 5}));
  EXPECT_EQ(devices::body::sim::bodyConfig(line.options).foot_mode,
            devices::body::sim::FootMode::kAlternate);
  EXPECT_EQ(line.options.faults.seed, 9u);
  EXPECT_DOUBLE_EQ(line.options.faults.corrupt_rate, 0.5);
  EXPECT_EQ(line.options.device("base").link.value_or(""), "/tmp/b");
  EXPECT_FALSE(line.options.device("body").link.has_value());
  EXPECT_FALSE(line.options.hosts("servo_bus"));
  EXPECT_EQ(devices::base::sim::baseConfig(line.options).battery_percent, 40);
  EXPECT_DOUBLE_EQ(devices::body::sim::bodyConfig(line.options).telemetry_rate_hz, 0.0);
  EXPECT_EQ(devices::servo_bus::sim::servoBusConfig(line.options).offline_ids,
            (std::vector<uint8_t>{7}));
  EXPECT_EQ(line.options.pace_baud, 0u);  // off unless asked for
  EXPECT_EQ(parse({"--pace-baud", "115200"}).options.pace_baud, 115200u);
}

TEST(RobotSimCommandLine, RejectsUnknownFlagsAndBadValues) {
  EXPECT_FALSE(parse({"--bogus"}).error.empty());
  EXPECT_FALSE(parse({"--pace-baud", "fast"}).error.empty());
  EXPECT_FALSE(parse({"--corrupt-rate", "1.5"}).error.empty());
  EXPECT_FALSE(parse({"--servo-ids", "1,x"}).error.empty());
  EXPECT_FALSE(parse({"--servo-ids", "255"}).error.empty());
  EXPECT_FALSE(parse({"--battery"}).error.empty());
  EXPECT_FALSE(parse({"--foot=1"}).error.empty());
  EXPECT_FALSE(parse({"--no-base", "--no-body", "--no-servo-bus"}).error.empty());
  EXPECT_TRUE(parse({"--help"}).help);
}

TEST(RobotSimCommandLine, HelpListsTheFlagsWithTheirDefaults) {
  const std::string text = usage();
  for (const char* expected :
       {"--battery PCT", "battery percent the base reports (default 87)", "--servo-ids 1,2",
        "(default 1,2)", "--telemetry-rate HZ", "(default 50)", "--servo-latency-ms MS",
        "(default 1.5)", "--no-servo-bus", "--foot-alternate", "--seed N", "--stats-file PATH",
        "--unplug-duration S", "Faults (seeded):"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << " missing from:\n" << text;
  }
}

}  // namespace
}  // namespace serial_robot_driver::sim
