// The echo device's diagnostic status, decided in the core.
#include <gtest/gtest.h>

#include "serial_robot_driver/devices/echo/echo_status.h"

namespace serial_robot_driver::devices::echo {
namespace {

TEST(EchoStatus, ErrorWhileThePortIsClosedWarnAfterAFailedPing) {
  EchoStats stats;
  core::StatusReport report = echoStatus(stats, {"/dev/ttyUSB9", false});
  EXPECT_EQ(report.level, core::StatusLevel::kError);
  EXPECT_EQ(report.message, "port /dev/ttyUSB9 is not open");
  EXPECT_EQ(report.hardware_id, "/dev/ttyUSB9");

  report = echoStatus(stats, {"/dev/ttyUSB9", true});
  EXPECT_EQ(report.level, core::StatusLevel::kOk);
  EXPECT_EQ(report.message, "no ping yet");
  EXPECT_EQ(report.find("last round trip ms"), nullptr);

  stats.pings = 3;
  stats.round_trips = 2;
  stats.timeouts = 1;
  stats.last_ping_failed = true;
  stats.last_round_trip = std::chrono::microseconds(1500);
  report = echoStatus(stats, {"/dev/ttyUSB9", true});
  EXPECT_EQ(report.level, core::StatusLevel::kWarn);
  EXPECT_EQ(report.message, "the last ping had no answer");
  ASSERT_NE(report.find("timeouts"), nullptr);
  EXPECT_EQ(*report.find("timeouts"), "1");
  EXPECT_EQ(*report.find("round trips"), "2");
  EXPECT_EQ(*report.find("last round trip ms"), "1.500");

  stats.last_ping_failed = false;
  report = echoStatus(stats, {"/dev/ttyUSB9", true});
  EXPECT_EQ(report.level, core::StatusLevel::kOk);
  EXPECT_EQ(report.message, "answering");
}

}  // namespace
}  // namespace serial_robot_driver::devices::echo
