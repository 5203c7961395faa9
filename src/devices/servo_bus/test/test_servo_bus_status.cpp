// The servo bus's diagnostic statuses: the bus (transactions, offline servos, unconfirmed stops,
// the poll's asked vs achieved rate over its window) and each polled servo's health.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_status.h"

namespace {

using namespace serial_robot_driver::devices::servo_bus;
using namespace serial_robot_driver::core;
using std::chrono::milliseconds;
using SteadyClock = std::chrono::steady_clock;

ServoBusSnapshot connectedBus() {
  ServoBusSnapshot bus;
  bus.port = {"/dev/ttyUSB1", true};
  bus.stats.transactions = 12;
  bus.stats.timeouts = 1;
  bus.stats.last_latency_ms = 1.234;
  bus.options.timeout = milliseconds(50);
  bus.options.retries = 2;
  bus.in_force.health_rate = 0.5;
  return bus;
}

TEST(ServoBusStatus, ConnectedCountsTransactionsAndListsTheBus) {
  ServoBusStatus watch;
  const StatusReport status = watch.update(connectedBus(), SteadyClock::now());
  EXPECT_EQ(status.level, StatusLevel::kOk);
  EXPECT_EQ(status.message, "12 transactions, 1 timeouts");
  EXPECT_EQ(status.hardware_id, "/dev/ttyUSB1");
  std::vector<std::string> keys;
  for (const auto& [key, value] : status.values) keys.push_back(key);
  EXPECT_EQ(keys, (std::vector<std::string>{"port",
                                            "connected",
                                            "transactions",
                                            "commands without answer",
                                            "timeouts",
                                            "retries",
                                            "mismatched answers",
                                            "garbled answers",
                                            "echoes skipped",
                                            "last latency (ms)",
                                            "max latency (ms)",
                                            "timeout (ms)",
                                            "retries per transaction",
                                            "dangerous writes armed",
                                            "servo_states published",
                                            "polled servos offline",
                                            "servo_commands moves sent",
                                            "servo_commands rejected",
                                            "servo_commands moves failed",
                                            "servos set moving",
                                            "motion locked (e_stop)",
                                            "motion frames refused when written",
                                            "stops not yet confirmed",
                                            "on shutdown",
                                            "health polls per second",
                                            "protect",
                                            "servo_states asked (per s)"}))
      << "no achieved rate before the first window is over";
  EXPECT_EQ(*status.find("last latency (ms)"), "1.23");
  EXPECT_EQ(*status.find("timeout (ms)"), "50");
  EXPECT_EQ(*status.find("retries per transaction"), "2");
  EXPECT_EQ(*status.find("dangerous writes armed"), "False");
  EXPECT_EQ(*status.find("polled servos offline"), "none");
  EXPECT_EQ(*status.find("servos set moving"), "none");
  EXPECT_EQ(*status.find("stops not yet confirmed"), "none");
  EXPECT_EQ(*status.find("on shutdown"), "stop");
  EXPECT_EQ(*status.find("health polls per second"), "0.5");
}

TEST(ServoBusStatus, APortDownWarnsAndOfflineServosWarnOnlyWhileItIsUp) {
  ServoBusSnapshot bus = connectedBus();
  bus.worker.offline_ids = {3, 7};
  bus.moving_ids = {1, 2};
  ServoBusStatus watch;
  StatusReport offline = watch.update(bus, SteadyClock::now());
  EXPECT_EQ(offline.level, StatusLevel::kWarn);
  EXPECT_EQ(offline.message, "polled servos not answering: 3, 7");
  EXPECT_EQ(*offline.find("polled servos offline"), "3, 7");
  EXPECT_EQ(*offline.find("servos set moving"), "1, 2");

  bus.port.connected = false;
  StatusReport down = watch.update(bus, SteadyClock::now());
  EXPECT_EQ(down.level, StatusLevel::kWarn);
  EXPECT_EQ(down.message, "servo bus port is not connected");
}

TEST(ServoBusStatus, UnconfirmedStopsAreAnErrorNamingTheJoints) {
  ServoBusSnapshot bus = connectedBus();
  bus.motion_locked = true;
  bus.pending_stops = {{3, 1, "not answered"}, {5, 2, "not seen at rest"}};
  ServoBusStatus watch;
  const StatusReport status = watch.update(bus, SteadyClock::now());
  EXPECT_EQ(status.level, StatusLevel::kError);
  EXPECT_EQ(status.message,
            "stop not yet known to have reached servo_3: not answered; servo_5: not seen at rest");
  EXPECT_EQ(*status.find("stops not yet confirmed"),
            "servo_3: not answered; servo_5: not seen at rest");
  EXPECT_EQ(*status.find("motion locked (e_stop)"), "True");
}

TEST(ServoBusStatus, TheAchievedRateIsMeasuredOverTheWindowAndWarnsBelow90Percent) {
  ServoBusSnapshot bus = connectedBus();
  bus.worker.asked_poll_rate = 20.0;
  ServoBusStatus watch;
  const SteadyClock::time_point start = SteadyClock::now();
  bus.worker.angles_polled = 100;
  watch.update(bus, start);
  bus.worker.angles_polled = 110;
  StatusReport early = watch.update(bus, start + milliseconds(1000));
  EXPECT_EQ(early.find("servo_states achieved (per s)"), nullptr) << "the window is 2 s";

  bus.worker.angles_polled = 136;  // 36 reads in 2 s: 18/s, exactly 90 % of 20
  StatusReport enough = watch.update(bus, start + milliseconds(2000));
  EXPECT_EQ(enough.level, StatusLevel::kOk);
  EXPECT_EQ(*enough.find("servo_states asked (per s)"), "20.0");
  EXPECT_EQ(*enough.find("servo_states achieved (per s)"), "18.0");

  bus.worker.angles_polled = 137;  // one more read over 1 s: the window keeps the last rate
  EXPECT_EQ(*watch.update(bus, start + milliseconds(3000)).find("servo_states achieved (per s)"),
            "18.0");
  bus.worker.angles_polled = 170;  // 34 in 2 s: 17/s
  StatusReport slow = watch.update(bus, start + milliseconds(4000));
  EXPECT_EQ(slow.level, StatusLevel::kWarn);
  EXPECT_EQ(slow.message,
            "servo_states: 20 reads/s asked, the bus delivers 17/s (the line or service calls are "
            "the limit: lower ~servo_bus/state_rate or raise the baud)");

  bus.port.connected = false;
  bus.worker.angles_polled = 170;
  StatusReport down = watch.update(bus, start + milliseconds(6000));
  EXPECT_EQ(down.message, "servo bus port is not connected") << "a port down is reason enough";
}

ServoHealthReport answering(uint8_t id) {
  ServoHealthReport report;
  report.id = id;
  report.polled = true;
  report.online = true;
  report.readings = {7400, 120, 890, 41, 0};
  return report;
}

TEST(ServoHealthStatus, OffOrNotPolledYetIsOk) {
  const StatusReport off = servoHealthStatus(3, 0.0, nullptr);
  EXPECT_EQ(off.level, StatusLevel::kOk);
  EXPECT_EQ(off.message, "servo 3: health poll off (~servo_bus/health_rate 0)");
  EXPECT_TRUE(off.values.empty());
  const ServoHealthReport report = answering(3);
  EXPECT_EQ(servoHealthStatus(3, 0.0, &report).message, off.message) << "off wins over a report";

  const StatusReport none = servoHealthStatus(3, 1.0, nullptr);
  EXPECT_EQ(none.level, StatusLevel::kOk);
  EXPECT_EQ(none.message, "servo 3: no health poll yet");
  ServoHealthReport unpolled;
  unpolled.id = 3;
  EXPECT_EQ(servoHealthStatus(3, 1.0, &unpolled).message, "servo 3: no health poll yet");
}

TEST(ServoHealthStatus, AServoThatDoesNotAnswerIsAnError) {
  ServoHealthReport report = answering(4);
  report.online = false;
  report.last_error = "no answer after 2 attempts";
  const StatusReport status = servoHealthStatus(4, 1.0, &report);
  EXPECT_EQ(status.level, StatusLevel::kError);
  EXPECT_EQ(status.message, "servo 4 does not answer: no answer after 2 attempts");
  EXPECT_EQ(status.values, (decltype(status.values){{"online", "False"}}));
}

TEST(ServoHealthStatus, ReadingsAndLimitsWithTheAssessmentsLevel) {
  ServoHealthReport report = answering(5);
  StatusReport unknown_limits = servoHealthStatus(5, 1.0, &report);
  EXPECT_EQ(unknown_limits.level, StatusLevel::kOk);
  EXPECT_EQ(unknown_limits.message, "servo 5 ok");
  EXPECT_EQ(*unknown_limits.find("limits"), "not read yet");
  EXPECT_EQ(*unknown_limits.find("voltage (mV)"), "7400");
  EXPECT_EQ(*unknown_limits.find("temperature (degC)"), "41");

  report.limits_known = true;
  report.limits = {6000, 8400, 65, 4000, 1500};
  report.assessment = {HealthLevel::kWarn, "servo 5: temperature 60 degC near over_temperature"};
  StatusReport warm = servoHealthStatus(5, 1.0, &report);
  EXPECT_EQ(warm.level, StatusLevel::kWarn);
  EXPECT_EQ(warm.message, "servo 5: temperature 60 degC near over_temperature");
  EXPECT_EQ(warm.find("limits"), nullptr);
  EXPECT_EQ(*warm.find("over_temperature (degC)"), "65");
  EXPECT_EQ(*warm.find("over_current (mA)"), "1500");
  EXPECT_EQ(warm.values.back().first, "relaxed for its temperature (protect)");

  report.assessment = {HealthLevel::kError, "servo 5: temperature 70 degC beyond"};
  report.overheated = true;
  StatusReport hot = servoHealthStatus(5, 1.0, &report);
  EXPECT_EQ(hot.level, StatusLevel::kError);
  EXPECT_EQ(hot.message,
            "servo 5: temperature 70 degC beyond; relaxed, moves refused until it has cooled");
  EXPECT_EQ(*hot.find("relaxed for its temperature (protect)"), "True");
}

TEST(ServoJointName, IsServoUnderscoreId) { EXPECT_EQ(servoJointName(12), "servo_12"); }

}  // namespace
