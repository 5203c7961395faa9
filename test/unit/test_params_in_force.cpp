// core::ParamsInForce (core/params_in_force.h): a runtime change is checked as the start-up
// parameters are, a refused value (NaN, infinite, zero where it must be positive) keeps the value
// in force, only an accepted change reaches the devices, and nothing does once stopped.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "serial_robot_driver/core/params_in_force.h"
#include "serial_robot_driver/devices/base/base_params.h"

namespace serial_robot_driver::core {
namespace {

using devices::base::kBaseSection;

/// A device that keeps the parameters of every retune().
class RetunedDevice : public Device {
 public:
  void start() override {}
  void shutdown() override {}
  StatusReport status() override { return {}; }
  void retune(const params::DriverParams& in_force) override { retunes.push_back(in_force); }

  std::vector<params::DriverParams> retunes;
};

double maxWheelSpeed(const params::DriverParams& params) {
  return params.section(kBaseSection).controller.max_wheel_speed;
}

class ParamsInForceTest : public ::testing::Test {
 protected:
  ParamsInForceTest() { start_.section(kBaseSection).controller.max_wheel_speed = 0.8; }

  params::DriverParams start_;
  RetunedDevice first_, second_;
};

TEST_F(ParamsInForceTest, AnAcceptedChangeIsInForceAndReachesEveryDevice) {
  ParamsInForce params(start_, {&first_, &second_}, nullptr);
  const params::TuningResult result = params.apply({{"base/max_wheel_speed", 0.5}});
  EXPECT_EQ(result.changes, std::vector<std::string>{"~base/max_wheel_speed = 0.5 (was 0.8)"});
  EXPECT_TRUE(result.refusals.empty());
  EXPECT_DOUBLE_EQ(maxWheelSpeed(result.applied), 0.5);
  EXPECT_DOUBLE_EQ(maxWheelSpeed(params.inForce()), 0.5);
  for (const RetunedDevice* device : {&first_, &second_}) {
    ASSERT_EQ(device->retunes.size(), 1u);
    EXPECT_DOUBLE_EQ(maxWheelSpeed(device->retunes[0]), 0.5);
  }
}

TEST_F(ParamsInForceTest, NothingReachesTheDevicesWhenNothingChanges) {
  ParamsInForce params(start_, {&first_}, nullptr);
  EXPECT_TRUE(params.apply({}).changes.empty());
  const params::TuningResult same = params.apply({{"base/max_wheel_speed", 0.8}});
  EXPECT_TRUE(same.changes.empty());
  EXPECT_DOUBLE_EQ(maxWheelSpeed(same.applied), 0.8);
  EXPECT_TRUE(first_.retunes.empty());
}

TEST_F(ParamsInForceTest, ARefusedValueKeepsTheValueInForceAndSaysWhy) {
  ParamsInForce params(start_, {&first_}, nullptr);
  for (double refused : {std::nan(""), -std::numeric_limits<double>::infinity(), 0.0, -1e308}) {
    const params::TuningResult result = params.apply({{"base/max_wheel_speed", refused}});
    ASSERT_EQ(result.refusals.size(), 1u) << refused;
    EXPECT_NE(result.refusals[0].find("keeping 0.8"), std::string::npos) << result.refusals[0];
    EXPECT_TRUE(result.changes.empty());
    EXPECT_DOUBLE_EQ(maxWheelSpeed(result.applied), 0.8);
  }
  EXPECT_DOUBLE_EQ(maxWheelSpeed(params.inForce()), 0.8);
  EXPECT_TRUE(first_.retunes.empty());
}

TEST_F(ParamsInForceTest, OnceStoppedNothingIsApplied) {
  ParamsInForce params(start_, {&first_}, nullptr);
  params.stop();
  params.stop();
  const params::TuningResult result = params.apply({{"base/max_wheel_speed", 0.5}});
  EXPECT_TRUE(result.changes.empty());
  EXPECT_TRUE(result.refusals.empty());
  EXPECT_DOUBLE_EQ(maxWheelSpeed(result.applied), 0.8);
  EXPECT_DOUBLE_EQ(maxWheelSpeed(params.inForce()), 0.8);
  EXPECT_TRUE(first_.retunes.empty());
}

}  // namespace
}  // namespace serial_robot_driver::core
