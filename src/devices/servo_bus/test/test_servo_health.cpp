// The health thresholds of a bus servo: WARN within 10 % of a limit, ERROR at or beyond it, unset
// limits ignored, the message naming the servo and the limit; the overheat guard's hysteresis.
#include <gtest/gtest.h>

#include "serial_robot_driver/devices/servo_bus/servo_health.h"

namespace {

using serial_robot_driver::devices::servo_bus::assessHealth;
using serial_robot_driver::devices::servo_bus::HealthLevel;
using serial_robot_driver::devices::servo_bus::OverheatGuard;
using serial_robot_driver::devices::servo_bus::ServoLimits;
using serial_robot_driver::devices::servo_bus::ServoReadings;

// The simulator's factory limits: 4500..14000 mV, 65 degC, 12000 mW, 3000 mA.
ServoLimits limits() {
  ServoLimits l;
  l.over_volt_low_mv = 4500;
  l.over_volt_high_mv = 14000;
  l.over_temperature_c = 65;
  l.over_power_mw = 12000;
  l.over_current_ma = 3000;
  return l;
}

ServoReadings nominal() {
  ServoReadings r;
  r.voltage_mv = 12000;
  r.current_ma = 20;
  r.power_mw = 240;
  r.temperature_c = 30;
  return r;
}

TEST(ServoHealth, NominalValuesAreOk) {
  const auto assessment =
      serial_robot_driver::devices::servo_bus::assessHealth(3, nominal(), limits());
  EXPECT_EQ(assessment.level, HealthLevel::kOk);
  EXPECT_EQ(assessment.message, "");
}

TEST(ServoHealth, TemperatureWithinTenPercentWarnsAndAtTheLimitIsAnError) {
  ServoReadings r = nominal();
  r.temperature_c = 58;  // 65 - 6.5 = 58.5: not yet within
  EXPECT_EQ(serial_robot_driver::devices::servo_bus::assessHealth(3, r, limits()).level,
            HealthLevel::kOk);
  r.temperature_c = 59;
  auto assessment = serial_robot_driver::devices::servo_bus::assessHealth(3, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kWarn);
  EXPECT_EQ(assessment.message,
            "servo 3: temperature 59 degC within 10 % of over_temperature 65 degC");
  r.temperature_c = 65;
  assessment = serial_robot_driver::devices::servo_bus::assessHealth(3, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kError);
  EXPECT_EQ(assessment.message,
            "servo 3: temperature 65 degC at or beyond over_temperature 65 degC");
}

TEST(ServoHealth, LowVoltageIsCheckedAgainstTheLowerLimit) {
  ServoReadings r = nominal();
  r.voltage_mv = 4950;  // 4500 + 450
  auto assessment = serial_robot_driver::devices::servo_bus::assessHealth(1, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kWarn);
  EXPECT_NE(assessment.message.find("over_volt_low 4500 mV"), std::string::npos);
  r.voltage_mv = 4951;
  EXPECT_EQ(serial_robot_driver::devices::servo_bus::assessHealth(1, r, limits()).level,
            HealthLevel::kOk);
  r.voltage_mv = 4000;
  assessment = serial_robot_driver::devices::servo_bus::assessHealth(1, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kError);
  EXPECT_EQ(assessment.message, "servo 1: voltage 4000 mV at or below over_volt_low 4500 mV");
}

TEST(ServoHealth, HighVoltageCurrentAndPowerEachHaveTheirLimit) {
  ServoReadings r = nominal();
  r.voltage_mv = 14500;
  EXPECT_NE(serial_robot_driver::devices::servo_bus::assessHealth(1, r, limits())
                .message.find("over_volt_high 14000 mV"),
            std::string::npos);
  r = nominal();
  r.current_ma = 2800;
  auto assessment = serial_robot_driver::devices::servo_bus::assessHealth(1, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kWarn);
  EXPECT_NE(assessment.message.find("over_current 3000 mA"), std::string::npos);
  r = nominal();
  r.power_mw = 12001;
  assessment = serial_robot_driver::devices::servo_bus::assessHealth(1, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kError);
  EXPECT_NE(assessment.message.find("over_power 12000 mW"), std::string::npos);
}

TEST(ServoHealth, ErrorsComeBeforeWarningsAndTheWorstLevelWins) {
  ServoReadings r = nominal();
  r.current_ma = 2900;   // warn
  r.temperature_c = 70;  // error
  const auto assessment = serial_robot_driver::devices::servo_bus::assessHealth(2, r, limits());
  EXPECT_EQ(assessment.level, HealthLevel::kError);
  EXPECT_EQ(assessment.message,
            "servo 2: temperature 70 degC at or beyond over_temperature 65 degC; current 2900 mA "
            "within 10 % of over_current 3000 mA");
}

TEST(ServoHealth, AnUnsetLimitIsNotChecked) {
  ServoReadings r = nominal();
  r.temperature_c = 200;
  ServoLimits l = limits();
  l.over_temperature_c = 0;
  EXPECT_EQ(serial_robot_driver::devices::servo_bus::assessHealth(1, r, l).level, HealthLevel::kOk);
}

TEST(OverheatGuard, TripsAtTheLimitAndClearsFiveDegreesBelow) {
  OverheatGuard guard;
  EXPECT_FALSE(guard.update(64, 65));
  EXPECT_TRUE(guard.update(65, 65));
  EXPECT_TRUE(guard.update(63, 65));
  EXPECT_TRUE(guard.update(61, 65));  // 4 degC below: still too warm
  EXPECT_FALSE(guard.update(60, 65));
  EXPECT_FALSE(guard.update(64, 65));
  EXPECT_TRUE(guard.update(66, 65));
  EXPECT_FALSE(guard.update(90, 0)) << "no limit set on the servo";
}

}  // namespace
