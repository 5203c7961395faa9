// Every device's parameter section by one path (params/device_sections.h): a typed key the
// module declares, copies that do not share, and a misused key refused loudly.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/core/typed_value.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/devices/body/gyro_bias.h"
#include "serial_robot_driver/devices/echo/echo_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::params {
namespace {

TEST(DeviceSections, EveryRegisteredDeviceHasItsOwnSectionWithItsPortParameters) {
  DriverParams params;
  for (const core::DeviceModule* device : core::registeredDevices()) {
    ASSERT_FALSE(device->sections.empty()) << device->name;
    EXPECT_STREQ(device->sections.front()->name(), device->name) << "its own section first";
    EXPECT_NO_THROW(params.portParams(*device)) << device->name;
  }
  // The defaults are the sections' own: the echo device is off unless asked for.
  EXPECT_FALSE(params.section(devices::echo::kEchoSection).enabled);
  EXPECT_TRUE(params.section(devices::base::kBaseSection).enabled);
}

TEST(DeviceSections, PortParametersAreTheDeviceSectionsOwn) {
  DriverParams params;
  params.portParams(*core::findDevice("base")).baud = 9600;
  params.section(devices::echo::kEchoSection).port = "/dev/ttyECHO";
  EXPECT_EQ(params.section(devices::base::kBaseSection).baud, 9600);
  EXPECT_EQ(params.portOf(*core::findDevice("echo")), "/dev/ttyECHO");
}

TEST(DeviceSections, ACopyHasSectionsOfItsOwn) {
  DriverParams original;
  DriverParams copy = original;
  copy.section(devices::body::kBodySection).joint_names = {"a", "b"};
  copy.section(devices::body::kImuSection).gyro_scale = 2.0;
  EXPECT_EQ(original.section(devices::body::kBodySection).joint_names,
            (std::vector<std::string>{"joint_1", "joint_2"}));
  EXPECT_EQ(original.section(devices::body::kImuSection).gyro_scale,
            devices::body::ImuParams().gyro_scale);
  original = copy;
  copy.section(devices::body::kImuSection).gyro_scale = 3.0;
  EXPECT_EQ(original.section(devices::body::kImuSection).gyro_scale, 2.0)
      << "assignment copies too";
}

TEST(DeviceSections, AKeyOfAnotherTypeOrAnUndeclaredSectionIsAProgrammingError) {
  DriverParams params;
  const SectionKey<devices::body::ImuParams> imu_under_the_base_name("base");
  EXPECT_THROW(params.section(imu_under_the_base_name), std::logic_error);
  const DriverParams& as_const = params;
  EXPECT_THROW(as_const.section(imu_under_the_base_name), std::logic_error);
  const SectionKey<devices::base::BaseParams> undeclared("no_such_device");
  EXPECT_THROW(params.section(undeclared), std::logic_error);
  EXPECT_THROW(params.sections.portParams("imu"), std::logic_error) << "no port parameters";
  EXPECT_THROW(params.sections.add(devices::base::kBaseSection), std::logic_error)
      << "declared twice";
}

TEST(TypedValue, ReadsBackOnlyAsTheStoredTypeAndCopiesDoNotShare) {
  core::TypedValue empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_THROW(empty.as<int>(), std::logic_error);
  core::TypedValue value = std::string("left");
  EXPECT_TRUE(value.holds<std::string>());
  EXPECT_THROW(value.as<int>(), std::logic_error);
  core::TypedValue copy = value;
  copy.as<std::string>() = "right";
  EXPECT_EQ(value.as<std::string>(), "left");
}

TEST(DeviceSections, TheBaseControllerTakesItsSectionAndTheNodeWideValues) {
  DriverParams params;
  params.section(devices::base::kBaseSection).controller.cmd_vel_timeout = 0.25;
  params.loop_rate = 40.0;
  params.portParams(*core::findDevice("base")).baud = 9600;
  const devices::base::BaseConfig config = devices::base::makeBaseConfig(params);
  EXPECT_EQ(config.cmd_vel_timeout, 0.25) << "the section's own";
  EXPECT_EQ(config.loop_rate, 40.0);
  EXPECT_EQ(config.baud, 9600);
  // The IMU's yaw variance (~imu/orientation_variance) now comes with its heading (the body's
  // HeadingSource): BaseDeviceTest.TheImuHeadingsVarianceIsTheOneItsSourceGives.
}

TEST(DeviceSections, TheGyroUnitsAreTheImuSectionsScaleAndAxisMap) {
  devices::body::ImuParams imu;
  imu.gyro_scale = 0.5;
  imu.axis_map = {"y", "-x", "z"};
  const devices::body::GyroUnits units = devices::body::gyroUnits(imu);
  EXPECT_EQ(units.gyro_scale, 0.5);
  EXPECT_EQ(units.axes.source, (std::array<int, 3>{1, 0, 2}));
  EXPECT_EQ(units.axes.sign, (std::array<int, 3>{1, -1, 1}));
}

}  // namespace
}  // namespace serial_robot_driver::params
