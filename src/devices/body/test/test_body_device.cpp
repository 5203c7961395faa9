// BodyDevice, the servo controller board whole in the core: built by its module in a DriverCore
// without any front end, on a port in memory; its joint commands are checked, refused and counted
// once for every front end, and every front end's outputs receive each telemetry frame.
#include <gtest/gtest.h>

#include <limits>
#include <mutex>
#include <vector>

#include "serial_robot_driver/core/driver_core.h"
#include "serial_robot_driver/devices/body/body_device.h"
#include "support/device_core_fixture.h"
#include "support/golden_frames.h"
#include "support/log_capture.h"
#include "support/memory_stream.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::body {
namespace {

using test_support::waitFor;

/// One front end's outputs: the joint readings it received, read from the test thread.
class Listener {
 public:
  BodyOutputs outputs() {
    return {[this](const BodyFrame& frame) {
      std::lock_guard<std::mutex> lock(mutex_);
      readings_.push_back(frame.joints);
      angle_scale_ = frame.imu.angle_scale;
    }};
  }
  std::vector<JointReadings> readings() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return readings_;
  }
  /// ~imu/angle_scale as the last frame was converted with.
  double angleScale() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return angle_scale_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<JointReadings> readings_;
  double angle_scale_ = 0.0;
};

class BodyDeviceTest : public test_support::DeviceCoreFixture<BodyDevice, Listener> {
 protected:
  BodyDeviceTest() : DeviceCoreFixture("body") {}
  BodyDevice& makeBody() { return makeDevice(); }
};

TEST_F(BodyDeviceTest, EveryFrontEndReceivesEachFramesJointReadings) {
  BodyDevice& body = makeBody();
  body.addOutputs(first_.outputs());
  body.addOutputs(second_.outputs());
  start();
  wire_.feed(golden::body::kTelemetryTwoServos);
  wire_.feed(golden::body::kTelemetryTwoServos);
  ASSERT_TRUE(waitFor(
      [&] { return first_.readings().size() == 2 && second_.readings().size() == 2; }, 5.0));
  for (const Listener* listener : {&first_, &second_}) {
    const JointReadings joints = listener->readings().front();
    EXPECT_EQ(joints.names, (std::vector<std::string>{"joint_1", "joint_2"}));
    ASSERT_EQ(joints.positions.size(), 2u);
    EXPECT_DOUBLE_EQ(joints.positions[0], 0.0) << "2048 ticks: the joint's zero";
    EXPECT_NEAR(joints.positions[1], -M_PI / 2, 1e-9) << "1024 ticks: a quarter turn back";
  }
}

TEST_F(BodyDeviceTest, ACommandWithABadPositionIsRefusedCountedAndLoggedOncePerSecond) {
  BodyDevice& body = makeBody();
  start();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(body.commandJoints({{"joint_1"}, {0.0}}), "");
  EXPECT_NE(body.commandJoints({{"joint_1"}, {nan}}), "");
  EXPECT_NE(body.commandJoints({{"joint_1", "joint_2"}, {0.0, -inf}}), "");
  const std::string huge = body.commandJoints({{"joint_2"}, {std::numeric_limits<double>::max()}});
  EXPECT_NE(huge, "") << "beyond the servo's reach: nothing written";
  EXPECT_NE(body.commandJoints({{"joint_1", "elbow"}, {0.0, 0.0}}), "");
  EXPECT_NE(body.commandJoints({{"joint_1"}, {0.0, 1.0}}), "");
  EXPECT_EQ(body.inputRefusalStats().refused.at("joint_commands"), 5u);
  EXPECT_EQ(logs_.count("joint_commands:"), 1u) << "throttled: one line a second";
}

TEST_F(BodyDeviceTest, WhileTheEStopHoldsACommandIsRefusedAndCountedByTheEStop) {
  BodyDevice& body = makeBody();
  core_->eStop().set(true);
  start();
  EXPECT_NE(body.commandJoints({{"joint_1"}, {0.0}}), "");
  EXPECT_EQ(core_->eStop().stats().refused.at("joint_commands"), 1u);
  EXPECT_FALSE(body.inputRefusalStats().refused.count("joint_commands")) << "a good message";
}

TEST_F(BodyDeviceTest, ARetuneTakesTheImuSection) {
  BodyDevice& body = makeBody();
  body.addOutputs(first_.outputs());
  ImuParams tuned = params_.section(kImuSection);
  tuned.angle_scale = 0.5;
  body.retune(tuned);
  start();
  wire_.feed(golden::body::kTelemetryTwoServos);
  ASSERT_TRUE(waitFor([&] { return first_.readings().size() == 1; }, 5.0));
  EXPECT_EQ(first_.angleScale(), 0.5);
}

}  // namespace
}  // namespace serial_robot_driver::devices::body
