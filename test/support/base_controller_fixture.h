// BaseControllerTest: a BaseController whose loop runs on a ManualClock (the loop thread runs; the
// test moves time) and writes to a fake port that records every frame.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "serial_robot_driver/devices/base/base_controller.h"
#include "support/golden_frames.h"
#include "support/manual_clock.h"

namespace serial_robot_driver::devices::base::base_controller_test {

using Bytes = std::vector<uint8_t>;
using std::chrono::milliseconds;

/// A controller whose loop runs on `clock`, started and waiting for its first tick; the frames it
/// writes go to `frames` when one is given (for tests with a configuration of their own).
inline std::unique_ptr<BaseController> startOnManualClock(
    const BaseConfig& config, BaseEvents events, const std::shared_ptr<core::ManualClock>& clock,
    std::vector<Bytes>* frames = nullptr) {
  auto controller = std::make_unique<BaseController>(
      config,
      [frames](const Bytes& frame) {
        if (frames != nullptr) frames->push_back(frame);
        return true;
      },
      std::move(events), clock);
  controller->start();
  clock->waitForLoop();
  return controller;
}

/// A cmd_vel as the device gives it (submitCommand()), returning once its frame is written: at
/// once on this thread, or by the loop (woken for it) when the line had no room yet.
inline CommandOutcome command(core::ManualClock& clock, BaseController& controller, double linear_x,
                              double angular_z,
                              std::optional<BaseController::Generation> accepted = std::nullopt) {
  CommandOutcome outcome = CommandOutcome::kStored;
  clock.stepIf([&] {
    outcome = controller.submitCommand(linear_x, angular_z, accepted);
    return outcome == CommandOutcome::kStored || outcome == CommandOutcome::kNotFinite;
  });
  return outcome;
}

/// The controller's loop runs at 50 Hz on a ManualClock that starts at t0: the first tick falls
/// due at t0 + 20 ms.
class BaseControllerTest : public ::testing::Test {
 protected:
  BaseControllerTest()
      : clock_(std::make_shared<core::ManualClock>(t0_)),
        controller_(
            config(), [this](const Bytes& frame) { return write(frame); }, events(), clock_) {
    controller_.start();
    clock_->waitForLoop();
  }

  BaseEvents events() {
    BaseEvents events;
    events.on_wheel_frame = [this](const WheelFrameSent& sent) { sent_.push_back(sent); };
    events.on_odometry = [this](const OdometrySample& sample) { odometry_.push_back(sample); };
    return events;
  }

  static BaseConfig config() {
    BaseConfig c;
    c.battery_poll_rate = 0;  // tests that want polling enable it on their own controller
    return c;
  }

  // Called on the loop thread while the test waits in a ManualClock step, or on the test thread
  // while the loop waits: the clock's mutex orders the two.
  bool write(const Bytes& frame) {
    if (!port_up_) return false;
    frames_.push_back(frame);
    return true;
  }

  // Declared before the controller, so they outlive its loop thread.
  std::vector<Bytes> frames_;
  std::vector<WheelFrameSent> sent_;
  std::vector<OdometrySample> odometry_;
  bool port_up_ = true;
  const core::Clock::time_point t0_ = core::Clock::now();
  std::shared_ptr<core::ManualClock> clock_;
  BaseController controller_;
};

}  // namespace serial_robot_driver::devices::base::base_controller_test
