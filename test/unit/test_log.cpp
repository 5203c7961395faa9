// The core's log (core/log.h): the sink a front end sets receives every line with its level, and
// a LogThrottle lets a repeated line through once per period.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/log.h"

namespace serial_robot_driver::core {
namespace {

TEST(CoreLog, TheSinkReceivesEachFormattedLineWithItsLevel) {
  std::vector<std::pair<LogLevel, std::string>> lines;
  setLogSink(
      [&lines](LogLevel level, const std::string& text) { lines.emplace_back(level, text); });
  log(LogLevel::kWarn, "port %s lost (%d)", "/dev/ttyUSB0", 5);
  log(LogLevel::kDebug, "closed");
  setLogSink({});  // stderr again
  log(LogLevel::kInfo, "not captured");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].first, LogLevel::kWarn);
  EXPECT_EQ(lines[0].second, "port /dev/ttyUSB0 lost (5)");
  EXPECT_EQ(lines[1].first, LogLevel::kDebug);
}

TEST(CoreLog, AThrottleLetsTheFirstLineThroughThenHoldsForItsPeriod) {
  LogThrottle hourly(3600.0);
  EXPECT_TRUE(hourly.pass());
  EXPECT_FALSE(hourly.pass());
  EXPECT_FALSE(hourly.pass());
  LogThrottle unthrottled(0.0);
  EXPECT_TRUE(unthrottled.pass());
  EXPECT_TRUE(unthrottled.pass());
}

}  // namespace
}  // namespace serial_robot_driver::core
