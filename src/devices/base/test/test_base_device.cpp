// BaseDevice, the base whole in the core: built by its module in a DriverCore without any front
// end, on a port in memory; its inputs check, refuse and count once for every front end, and every
// front end's outputs receive the same readings.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/devices/base/base_device.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "support/device_core_fixture.h"
#include "support/golden_frames.h"
#include "support/log_capture.h"
#include "support/memory_stream.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::base {
namespace {

using test_support::waitFor;

/// One front end's outputs: what it received, read from the test thread.
class Listener {
 public:
  BaseOutputs outputs() {
    BaseOutputs outputs;
    outputs.wheel_frame = [this](const WheelFrameSent& sent) {
      std::lock_guard<std::mutex> lock(mutex_);
      frames_.push_back(sent);
    };
    outputs.odometry = [this](const OdometrySample& sample) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++odometry_;
      last_odometry_ = sample;
    };
    return outputs;
  }
  std::vector<WheelFrameSent> frames() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }
  int odometry() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return odometry_;
  }
  OdometrySample lastOdometry() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_odometry_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<WheelFrameSent> frames_;
  int odometry_ = 0;
  OdometrySample last_odometry_;
};

class BaseDeviceTest : public test_support::DeviceCoreFixture<BaseDevice, Listener> {
 protected:
  BaseDeviceTest() : DeviceCoreFixture("base") {}
  BaseDevice& makeBase() { return makeDevice(); }
};

TEST_F(BaseDeviceTest, TheCoreBuildsTheBaseFromItsModuleWithoutAFrontEnd) {
  makeBase();
  ASSERT_EQ(core_->devices().size(), 1u);
  EXPECT_NE(dynamic_cast<BaseDevice*>(core_->device("base")), nullptr);
  EXPECT_EQ(core_->device("body"), nullptr) << "disabled";
}

TEST_F(BaseDeviceTest, EveryFrontEndReceivesEachWheelFrameAndOdometrySample) {
  BaseDevice& base = makeBase();
  base.addOutputs(first_.outputs());
  base.addOutputs(second_.outputs());
  start();
  ASSERT_TRUE(waitFor(
      [&] {
        return first_.frames().size() >= 3 && second_.frames().size() >= 3 &&
               first_.odometry() >= 1 && second_.odometry() >= 1;
      },
      5.0));
  core_->shutdown();  // the last words reach both as well
  const std::vector<WheelFrameSent> a = first_.frames();
  const std::vector<WheelFrameSent> b = second_.frames();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].seq, b[i].seq);
}

TEST_F(BaseDeviceTest, ACommandThatIsNotFiniteIsRefusedCountedAndLoggedOncePerSecond) {
  BaseDevice& base = makeBase();
  start();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(base.commandTwist({0.1, 0.0}), "");
  const std::string refusal = base.commandTwist({nan, 0.0});
  EXPECT_NE(refusal.find("not finite"), std::string::npos) << refusal;
  EXPECT_NE(base.commandTwist({0.0, inf}), "");
  EXPECT_NE(base.commandTwist({-inf, nan}), "");
  EXPECT_EQ(base.inputRefusalStats().refused.at("cmd_vel"), 3u);
  EXPECT_EQ(base.controller().stats().rejected_commands, 3u) << "zero speed commanded instead";
  EXPECT_EQ(logs_.count("cmd_vel rejected"), 1u) << "throttled: one line a second";
}

TEST_F(BaseDeviceTest, AHugeCommandIsObeyedAtNoMoreThanTheWheelSpeedLimit) {
  BaseDevice& base = makeBase();
  base.addOutputs(first_.outputs());
  start();
  const double huge = std::numeric_limits<double>::max();
  EXPECT_EQ(base.commandTwist({huge, -huge}), "");
  ASSERT_TRUE(waitFor(
      [&] {
        const auto frames = first_.frames();
        return !frames.empty() && !frames.back().speeds.isZero(0.0);
      },
      5.0));
  const double limit = params_.section(kBaseSection).controller.max_wheel_speed;
  for (const WheelFrameSent& sent : first_.frames()) {
    EXPECT_LE(std::abs(sent.speeds.x()), limit + 1e-9);
    EXPECT_LE(std::abs(sent.speeds.y()), limit + 1e-9);
  }
  EXPECT_FALSE(base.inputRefusalStats().refused.count("cmd_vel"));
}

TEST_F(BaseDeviceTest, WhileTheEStopHoldsACommandIsRefusedAndCountedByTheEStop) {
  BaseDevice& base = makeBase();
  core_->eStop().set(true);
  start();
  EXPECT_NE(base.commandTwist({0.1, 0.0}), "");
  EXPECT_EQ(core_->eStop().stats().refused.at("cmd_vel"), 1u);
  EXPECT_FALSE(base.inputRefusalStats().refused.count("cmd_vel")) << "a good message";
  EXPECT_EQ(base.motionInForce(), "");
}

TEST_F(BaseDeviceTest, RequestsAnswerWhatBecameOfThem) {
  BaseDevice& base = makeBase();
  const core::Outcome down = base.reset();
  EXPECT_FALSE(down.success);
  EXPECT_EQ(down.message, "base port memory is not connected");
  start();
  EXPECT_TRUE(base.reset().success);
  EXPECT_TRUE(base.clearEncoders().success);
  const core::Outcome odometry = base.resetOdometry();
  EXPECT_TRUE(odometry.success);
  EXPECT_EQ(odometry.message, "odometry pose reset to zero");
}

TEST_F(BaseDeviceTest, ARetuneTakesTheBaseSection) {
  BaseDevice& base = makeBase();
  BaseParams tuned = params_.section(kBaseSection);
  tuned.controller.max_wheel_speed = 0.3;
  tuned.battery_warn_percent = 50;
  base.retune(tuned);
  EXPECT_EQ(base.controller().config().max_wheel_speed, 0.3);
  EXPECT_EQ(base.tuned()->battery_warn_percent, 50);
  EXPECT_EQ(base.params().battery_warn_percent, 20) << "as started";
}

TEST_F(BaseDeviceTest, ThePortsComingsAndGoingsAreLoggedByTheCore) {
  makeBase();
  start();
  EXPECT_TRUE(waitFor([&] { return logs_.count("port memory connected") == 1; }, 5.0));
  core_->shutdown();
  EXPECT_EQ(logs_.count("lost"), 0u) << "closing is no outage";
}

TEST_F(BaseDeviceTest, TheImuHeadingsVarianceIsTheOneItsSourceGives) {
  // The body on the same port offers its IMU's yaw with ~imu/orientation_variance.
  params_.portParams(*core::findDevice("body")).enabled = true;
  params_.section(body::kImuSection).orientation_variance = 0.05;
  params_.section(kBaseSection).controller.use_imu_heading = true;
  BaseDevice& base = makeBase();
  base.addOutputs(first_.outputs());
  start();
  ASSERT_TRUE(waitFor(
      [&] {
        wire_.feed(golden::body::kTelemetryTwoServos);  // keeps the IMU's heading fresh
        return first_.lastOdometry().imu_heading;
      },
      5.0));
  EXPECT_EQ(first_.lastOdometry().yaw_variance, 0.05);
}

}  // namespace
}  // namespace serial_robot_driver::devices::base
