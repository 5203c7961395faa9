// device::EventRate: the telemetry rate's verdict and keys, as diagnostic_updater's
// FrequencyStatus gives them (window of five status calls, 10 % tolerance).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "serial_robot_driver/core/event_rate.h"

namespace serial_robot_driver::core {
namespace {

struct FakeClock {
  double now = 100.0;
};

std::string valueOf(const StatusReport& report, const std::string& key) {
  const std::string* value = report.find(key);
  return value ? *value : "<missing>";
}

TEST(EventRate, NoEventsIsAnError) {
  FakeClock clock;
  EventRate rate(1.0, 1000.0, [&] { return clock.now; });
  clock.now += 1.0;
  StatusReport report;
  rate.addTo(report);
  EXPECT_EQ(report.level, StatusLevel::kError);
  EXPECT_EQ(report.message, "No events recorded.");
  EXPECT_EQ(valueOf(report, "Events in window"), "0");
}

TEST(EventRate, ARateInRangeIsMetAndReported) {
  FakeClock clock;
  EventRate rate(1.0, 1000.0, [&] { return clock.now; });
  for (int i = 0; i < 50; ++i) rate.tick();
  clock.now += 2.0;
  StatusReport report;
  rate.addTo(report);
  EXPECT_EQ(report.level, StatusLevel::kOk);
  EXPECT_EQ(report.message, "Desired frequency met");
  EXPECT_EQ(valueOf(report, "Events in window"), "50");
  EXPECT_EQ(valueOf(report, "Events since startup"), "50");
  EXPECT_EQ(valueOf(report, "Duration of window (s)"), "2.000000");
  EXPECT_EQ(valueOf(report, "Actual frequency (Hz)"), "25.000000");
  EXPECT_EQ(valueOf(report, "Minimum acceptable frequency (Hz)"), "0.900000");
  EXPECT_EQ(valueOf(report, "Maximum acceptable frequency (Hz)"), "1100.000000");
  EXPECT_EQ(report.find("Target frequency (Hz)"), nullptr);
}

TEST(EventRate, TooFewOrTooManyEventsWarn) {
  FakeClock clock;
  EventRate slow(1.0, 1000.0, [&] { return clock.now; });
  EventRate fast(1.0, 2.0, [&] { return clock.now; });
  slow.tick();
  for (int i = 0; i < 30; ++i) fast.tick();
  clock.now += 10.0;
  StatusReport slow_report, fast_report;
  slow.addTo(slow_report);
  fast.addTo(fast_report);
  EXPECT_EQ(slow_report.level, StatusLevel::kWarn);
  EXPECT_EQ(slow_report.message, "Frequency too low.");
  EXPECT_EQ(fast_report.level, StatusLevel::kWarn);
  EXPECT_EQ(fast_report.message, "Frequency too high.");
}

TEST(EventRate, TheWindowReachesBackFiveCalls) {
  FakeClock clock;
  EventRate rate(1.0, 1.0, [&] { return clock.now; });
  for (int call = 0; call < 6; ++call) {
    rate.tick();
    clock.now += 1.0;
    StatusReport report;
    rate.addTo(report);
    if (call == 5) {
      // The sixth call measures from the first one: five events over five seconds.
      EXPECT_EQ(valueOf(report, "Events in window"), "5");
      EXPECT_EQ(valueOf(report, "Duration of window (s)"), "5.000000");
      EXPECT_EQ(valueOf(report, "Target frequency (Hz)"), "1.000000");
      EXPECT_EQ(report.find("Maximum acceptable frequency (Hz)") != nullptr, true);
    }
  }
}

}  // namespace
}  // namespace serial_robot_driver::core
