// The base's diagnostic status from its statistics: the link, silence, FF errors, the battery
// against its warn / error percent, the e-stop and the odom heading source.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "serial_robot_driver/devices/base/base_status.h"

namespace {

using namespace serial_robot_driver::devices::base;
using namespace serial_robot_driver::core;
using serial_robot_driver::kinematics::HeadingSource;

const PortState kUp{"/dev/ttyUSB0", true};
const BatteryLimits kLimits{20, 10};

std::vector<std::string> keysOf(const StatusReport& status) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : status.values) keys.push_back(key);
  return keys;
}

TEST(BaseStatus, ARunningBaseIsDrivingWithEveryCounter) {
  BaseStats stats;
  stats.speed_frames = 100;
  stats.min_immediate_interval_ms = 0.5;
  stats.worst_period_ms = 21.25;
  const StatusReport status = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(status.level, StatusLevel::kOk);
  EXPECT_EQ(status.message, "driving");
  EXPECT_EQ(status.hardware_id, "/dev/ttyUSB0");
  EXPECT_EQ(keysOf(status), (std::vector<std::string>{"port",
                                                      "connected",
                                                      "speed frames out",
                                                      "immediate frames (new cmd_vel)",
                                                      "e-stop engaged",
                                                      "cmd_vel ignored (e-stop)",
                                                      "cmd_vel voided (e-stop engaged after it "
                                                      "was accepted)",
                                                      "resets sent",
                                                      "FF timeout errors received",
                                                      "FF timeout errors while running",
                                                      "min immediate frame spacing (ms)",
                                                      "battery requests",
                                                      "battery replies",
                                                      "unknown replies",
                                                      "bad replies",
                                                      "write failures",
                                                      "cmd_vel timeouts",
                                                      "rejected cmd_vel (NaN/Inf)",
                                                      "loop overruns",
                                                      "loop internal errors",
                                                      "last loop internal error",
                                                      "last loop period (ms)",
                                                      "worst loop period (ms)"}))
      << "no battery, heading or silence keys before there is something to say";
  EXPECT_EQ(*status.find("port"), "/dev/ttyUSB0");
  EXPECT_EQ(*status.find("connected"), "True");
  EXPECT_EQ(*status.find("speed frames out"), "100");
  EXPECT_EQ(*status.find("min immediate frame spacing (ms)"), "0.500");
  EXPECT_EQ(*status.find("worst loop period (ms)"), "21.250");
}

TEST(BaseStatus, APortDownIsAnErrorAndHidesTheBasesOwnComplaints) {
  BaseStats stats;
  stats.base_silent = true;
  stats.seconds_without_reply = 12.0;
  stats.seconds_since_running_timeout_error = 1.0;
  const StatusReport status = baseStatus(stats, {"/dev/ttyUSB0", false}, kLimits);
  EXPECT_EQ(status.level, StatusLevel::kError);
  EXPECT_EQ(status.message, "port /dev/ttyUSB0 not connected");
  EXPECT_EQ(*status.find("connected"), "False");
  EXPECT_EQ(*status.find("seconds without reply"), "12.0");
}

TEST(BaseStatus, ASilentBaseIsAnErrorARecentFfAWarning) {
  BaseStats stats;
  stats.seconds_without_reply = 4.6;
  EXPECT_EQ(baseStatus(stats, kUp, kLimits).level, StatusLevel::kOk)
      << "unanswered, but not yet silent";
  stats.base_silent = true;
  StatusReport silent = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(silent.level, StatusLevel::kError);
  EXPECT_EQ(silent.message, "no reply from the base for 5 s");

  stats = BaseStats{};
  stats.seconds_since_running_timeout_error = 9.9;
  StatusReport recent = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(recent.level, StatusLevel::kWarn);
  EXPECT_EQ(recent.message, "base reported a timeout error (FF) 10 s ago: frames were lost");
  stats.seconds_since_running_timeout_error = kRecentTimeoutErrorS;
  EXPECT_EQ(baseStatus(stats, kUp, kLimits).level, StatusLevel::kOk) << "10 s on it is history";
}

TEST(BaseStatus, TheBatteryWarnsBelowWarnPercentAndErrsBelowErrorPercent) {
  BaseStats stats;
  stats.battery_percent = 20;
  StatusReport at_warn = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(at_warn.level, StatusLevel::kOk) << "at the limit is not below it";
  EXPECT_EQ(*at_warn.find("battery (%)"), "20");
  EXPECT_EQ(at_warn.values.back().first, "battery (%)");

  stats.battery_percent = 19;
  StatusReport low = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(low.level, StatusLevel::kWarn);
  EXPECT_EQ(low.message, "battery 19 % (below 20 %)");

  stats.battery_percent = 10;
  EXPECT_EQ(baseStatus(stats, kUp, kLimits).level, StatusLevel::kWarn);
  stats.battery_percent = 9;
  StatusReport empty = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(empty.level, StatusLevel::kError);
  EXPECT_EQ(empty.message, "battery 9 % (below 10 %)");
}

TEST(BaseStatus, EveryProblemIsNamedWorstLevelFirst) {
  BaseStats stats;
  stats.base_silent = true;
  stats.seconds_without_reply = 30.0;
  stats.battery_percent = 15;
  stats.e_stop = true;
  const StatusReport status = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(status.level, StatusLevel::kError);
  EXPECT_EQ(status.message,
            "no reply from the base for 30 s; battery 15 % (below 20 %); e-stop engaged: holding "
            "zero speed");
  EXPECT_EQ(*status.find("e-stop engaged"), "True");
}

TEST(BaseStatus, AnInternalErrorInTheLoopWarnsAndNamesTheLastOne) {
  BaseStats stats;
  stats.internal_errors = 3;
  stats.last_internal_error = "odom went wrong";
  const StatusReport status = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(status.level, StatusLevel::kWarn);
  EXPECT_EQ(status.message, "3 internal errors in the control loop");
  EXPECT_EQ(*status.find("loop internal errors"), "3");
  EXPECT_EQ(*status.find("last loop internal error"), "odom went wrong");
}

TEST(BaseStatus, OdomWithoutTheImuHeadingWarns) {
  BaseStats stats;
  stats.heading_source = HeadingSource::kImu;
  stats.imu_heading_fallbacks = 2;
  stats.imu_yaw_age = 0.25;
  StatusReport fused = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(fused.level, StatusLevel::kOk);
  ASSERT_GE(fused.values.size(), 3u);
  EXPECT_EQ(fused.values[0].first, "odom heading source") << "the heading keys come first";
  EXPECT_EQ(fused.values[0].second, "IMU");
  EXPECT_EQ(*fused.find("odom heading IMU fallbacks"), "2");
  EXPECT_EQ(*fused.find("odom heading IMU yaw age (s)"), "0.250000");

  stats.heading_source = HeadingSource::kImuStale;
  stats.imu_yaw_age.reset();
  StatusReport stale = baseStatus(stats, kUp, kLimits);
  EXPECT_EQ(stale.level, StatusLevel::kWarn);
  EXPECT_EQ(stale.message, "odom heading: commanded (IMU yaw stale)");
  EXPECT_EQ(*stale.find("odom heading IMU yaw age (s)"), "none yet");
}

}  // namespace
