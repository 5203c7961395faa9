// ServoBusDevice, the bus servos whole in the core: built by its module in a DriverCore without
// any front end, on a port in memory; servo_commands are checked, refused and counted once for
// every front end.
#include <gtest/gtest.h>

#include <limits>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_device.h"
#include "support/log_capture.h"
#include "support/memory_stream.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

class ServoBusDeviceTest : public ::testing::Test {
 protected:
  ServoBusDeviceTest() {
    params_.portParams(*core::findDevice("servo_bus")).port = "memory";
    for (const char* other : {"base", "body"}) {
      params_.portParams(*core::findDevice(other)).enabled = false;
    }
    core_ = std::make_unique<core::DriverCore>(params_, test_support::memoryStreams(wire_));
    // Built by the bus module's make_device: a ServoBusDevice.
    bus_ = static_cast<ServoBusDevice*>(core_->device("servo_bus"));
  }
  ~ServoBusDeviceTest() override { core_->shutdown(); }

  test_support::LogCapture logs_;  // outlives the core's threads, which may log
  test_support::MemoryWire wire_;  // outlives the core's link
  params::DriverParams params_;
  std::unique_ptr<core::DriverCore> core_;
  ServoBusDevice* bus_ = nullptr;
};

TEST_F(ServoBusDeviceTest, ACommandThatDoesNotCheckOutIsRefusedCountedAndLoggedOncePerPeriod) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(bus_->commandServos({{"servo_1"}, {0.5}, {}}), "");
  const std::string refusal = bus_->commandServos({{"servo_1"}, {nan}, {}});
  EXPECT_NE(refusal.find("non-finite"), std::string::npos) << refusal;
  EXPECT_NE(bus_->commandServos({{"servo_1"}, {0.0}, {-inf}}), "");
  EXPECT_NE(bus_->commandServos({{"servo_1", "servo_2"}, {0.0}, {}}), "");
  EXPECT_NE(bus_->commandServos({{"servo_999"}, {0.0}, {}}), "");
  EXPECT_EQ(bus_->inputRefusalStats().refused.at("servo_commands"), 4u);
  EXPECT_EQ(logs_.count("servo_commands rejected"), 1u) << "throttled";
  // The bus's status counts them as well.
  const core::StatusReport status = bus_->status();
  std::string rejected = "(absent)";
  for (const auto& [key, value] : status.values) {
    if (key == "servo_commands rejected") rejected = value;
  }
  EXPECT_EQ(rejected, "4");
}

TEST_F(ServoBusDeviceTest, WhileTheEStopHoldsACommandIsRefusedAndCountedByTheEStop) {
  core_->eStop().set(true);
  EXPECT_NE(bus_->commandServos({{"servo_1"}, {0.5}, {}}), "");
  EXPECT_EQ(core_->eStop().stats().refused.at("servo_commands"), 1u);
  EXPECT_FALSE(bus_->inputRefusalStats().refused.count("servo_commands")) << "a good message";
}

TEST_F(ServoBusDeviceTest, ARetuneTakesTheBusSection) {
  ServoBusParams tuned = params_.section(kServoBusSection);
  tuned.bus.poll_rate = 7.0;
  bus_->retune(tuned);
  EXPECT_EQ(bus_->bus().settings().poll_rate, 7.0);
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
