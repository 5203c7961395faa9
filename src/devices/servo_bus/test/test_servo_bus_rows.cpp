// The bus's converted rows: ~servo_bus/timeout (seconds) bound to the client's milliseconds,
// relax_power_mw to a uint16_t, on_shutdown to the action. Each check sees the value as written,
// before the conversion could hide what is wrong with it.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "serial_robot_driver/devices/servo_bus/servo_bus_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using std::chrono::milliseconds;

/// The message of the ParameterError that setting `key` to `value` throws; empty when none.
std::string refusalOfSetting(params::DriverParams& p, const std::string& key,
                             const params::ParamValue& value) {
  try {
    params::specFor(key).set(p, value);
  } catch (const params::ParameterError& error) {
    EXPECT_EQ(error.name(), key);
    return error.what();
  }
  return "";
}

TEST(ServoBusRows, TimeoutInSecondsIsTheClientsMilliseconds) {
  params::DriverParams p;
  EXPECT_EQ(params::specFor("servo_bus/timeout").get(p), params::ParamValue(0.05))
      << "the client's default";
  params::specFor("servo_bus/timeout").set(p, 0.25);
  EXPECT_EQ(p.section(kServoBusSection).bus.client.timeout, milliseconds(250));
  EXPECT_EQ(params::specFor("servo_bus/timeout").get(p), params::ParamValue(0.25));
  EXPECT_NO_THROW(p.validate());
}

TEST(ServoBusRows, ANonPositiveTimeoutIsRefusedAsWrittenAndTheFieldKeepsItsValue) {
  for (const double seconds : {0.0, -0.0004, -2.0}) {
    SCOPED_TRACE(seconds);
    params::DriverParams p;
    const std::string why = refusalOfSetting(p, "servo_bus/timeout", seconds);
    EXPECT_NE(why.find("~servo_bus/timeout"), std::string::npos) << why;
    // -0.0004 s rounds to 0 ms: the message must still show what the user wrote.
    EXPECT_NE(why.find("> 0 (got " + params::toText(seconds) + ")"), std::string::npos) << why;
    EXPECT_EQ(p.section(kServoBusSection).bus.client.timeout, milliseconds(50));
  }
  params::DriverParams too_long;
  EXPECT_NE(refusalOfSetting(too_long, "servo_bus/timeout", 5.5).find("at most 5 s"),
            std::string::npos);
}

TEST(ServoBusRows, APositiveTimeoutNeverBecomesZeroMilliseconds) {
  params::DriverParams p;
  params::specFor("servo_bus/timeout").set(p, 0.0004);
  EXPECT_EQ(p.section(kServoBusSection).bus.client.timeout, milliseconds(1));
  params::specFor("servo_bus/timeout").set(p, 0.0126);
  EXPECT_EQ(p.section(kServoBusSection).bus.client.timeout, milliseconds(13))
      << "rounded to the nearest ms";
}

TEST(ServoBusRows, ATimeoutSetInCodeIsCheckedByValidate) {
  params::DriverParams p;
  p.section(kServoBusSection).bus.client.timeout = milliseconds(0);
  EXPECT_THROW(params::specFor("servo_bus/timeout").check(p), params::ParameterError);
  EXPECT_THROW(p.validate(), params::ParameterError);
  p.section(kServoBusSection).bus.client.timeout = milliseconds(1);
  EXPECT_NO_THROW(p.validate());
}

TEST(ServoBusRows, PowerAndShutdownActionAreCheckedBeforeTheyAreConverted) {
  params::DriverParams p;
  EXPECT_NE(refusalOfSetting(p, "servo_bus/relax_power_mw", -1).find("0..65535 mW"),
            std::string::npos);
  EXPECT_NE(refusalOfSetting(p, "servo_bus/relax_power_mw", 65536).find("0..65535 mW"),
            std::string::npos);
  EXPECT_EQ(p.section(kServoBusSection).bus.relax_power_mw, 50) << "not wrapped into a uint16_t";
  EXPECT_NE(refusalOfSetting(p, "servo_bus/on_shutdown", std::string("halt")).find("got 'halt'"),
            std::string::npos);
  EXPECT_EQ(p.section(kServoBusSection).bus.on_shutdown, ShutdownAction::kStop);
  params::specFor("servo_bus/on_shutdown").set(p, std::string("relax"));
  params::specFor("servo_bus/relax_power_mw").set(p, 500);
  EXPECT_EQ(p.section(kServoBusSection).bus.on_shutdown, ShutdownAction::kRelax);
  EXPECT_EQ(p.section(kServoBusSection).bus.relax_power_mw, 500);
  EXPECT_EQ(params::specFor("servo_bus/on_shutdown").get(p),
            params::ParamValue(std::string("relax")));
}

TEST(ServoBusRows, ADisabledBusValuesAreNotChecked) {
  params::DriverParams p;
  p.section(kServoBusSection).enabled = false;
  EXPECT_EQ(refusalOfSetting(p, "servo_bus/timeout", 0.0), "");
  EXPECT_EQ(refusalOfSetting(p, "servo_bus/on_shutdown", std::string("halt")), "");
  EXPECT_NO_THROW(p.validate());
}

TEST(ServoBusRows, TuningRefusesABadTimeoutAndKeepsTheOneInForce) {
  params::DriverParams in_force;
  params::specFor("servo_bus/timeout").set(in_force, 0.2);
  const params::TuningResult refused =
      params::tuneParams(in_force, {{"servo_bus/timeout", 0.0}, {"servo_bus/retries", 3}});
  EXPECT_EQ(refused.applied.section(kServoBusSection).bus.client.timeout, milliseconds(200));
  EXPECT_EQ(refused.applied.section(kServoBusSection).bus.client.retries, 3)
      << "the valid part applies";
  ASSERT_EQ(refused.refusals.size(), 1u);
  EXPECT_NE(refused.refusals[0].find("~servo_bus/timeout = 0 refused"), std::string::npos)
      << refused.refusals[0];
  EXPECT_NE(refused.refusals[0].find("keeping 0.2"), std::string::npos) << refused.refusals[0];
  EXPECT_EQ(refused.changes, std::vector<std::string>{"~servo_bus/retries = 3 (was 1)"});

  const params::TuningResult applied = params::tuneParams(in_force, {{"servo_bus/timeout", 0.3}});
  EXPECT_TRUE(applied.refusals.empty());
  EXPECT_EQ(applied.applied.section(kServoBusSection).bus.client.timeout, milliseconds(300));
  EXPECT_EQ(applied.changes, std::vector<std::string>{"~servo_bus/timeout = 0.3 (was 0.2)"});
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
