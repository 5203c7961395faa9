#include "serial_robot_driver/devices/base/base_device.h"

#include <chrono>
#include <cstdio>
#include <sstream>

#include "serial_robot_driver/devices/base/base_status.h"

namespace serial_robot_driver::devices::base {

using core::log;
using core::LogLevel;

BaseDevice::BaseDevice(const params::DriverParams& params, core::SerialLink& link,
                       std::shared_ptr<core::LoopClock> clock)
    : link_(link),
      replaying_(!params.replay_bag.empty()),
      loop_rate_(params.loop_rate),
      params_(params.section(kBaseSection)),
      tuned_(std::make_shared<const BaseParams>(params_)),
      controller_(makeBaseConfig(params), link.writer(), events(), std::move(clock)) {
  link.addListener(&controller_);
}

BaseEvents BaseDevice::events() {
  // outputs_ is complete before the controller can report (addOutputs() before start()).
  BaseEvents events;
  events.on_wheel_frame = [this](const WheelFrameSent& sent) {
    for (const BaseOutputs& outputs : outputs_) {
      if (outputs.wheel_frame) outputs.wheel_frame(sent);
    }
  };
  events.on_odometry = [this](const OdometrySample& sample) {
    for (const BaseOutputs& outputs : outputs_) {
      if (outputs.odometry) outputs.odometry(sample);
    }
  };
  events.on_battery = [this](uint8_t percent, core::Clock::time_point arrival) {
    const BatteryReading reading = batteryReading(percent);
    for (const BaseOutputs& outputs : outputs_) {
      if (outputs.battery) outputs.battery(reading, arrival);
    }
  };
  events.on_cmd_vel_timeout = [this] {
    if (!timeout_log_.pass()) return;
    log(LogLevel::kInfo, "no cmd_vel for %.2f s (base/cmd_vel_timeout): commanding zero speed",
        tuned()->controller.cmd_vel_timeout);
  };
  events.on_silent = [this](double seconds) {
    if (!silent_log_.pass()) return;
    log(LogLevel::kError, "no reply from the base on %s for %.1f s (battery requests unanswered)",
        link_.options().path.c_str(), seconds);
  };
  events.on_timeout_error = [this] {
    if (!timeout_error_log_.pass()) return;
    log(LogLevel::kWarn, "base reported a connection-timeout error (FF): sending Reset");
  };
  events.on_heading_source = [this](kinematics::HeadingSource source) { logHeadingSource(source); };
  events.on_unknown_reply = [this](const Frame& frame) {
    if (!unknown_reply_log_.pass()) return;
    log(LogLevel::kDebug, "base sent a frame with unknown MSGID 0x%02X", frame.msg_id);
  };
  return events;
}

void BaseDevice::logHeadingSource(kinematics::HeadingSource source) {
  if (source == kinematics::HeadingSource::kImu) {
    log(LogLevel::kInfo, "odom heading: following the IMU's yaw (base/use_imu_heading)");
  } else if (source == kinematics::HeadingSource::kImuStale) {
    log(LogLevel::kWarn,
        "odom heading: no IMU yaw for %.2f s (is the body's telemetry flowing?); integrating "
        "the commanded turn from the last fused heading until it returns",
        std::chrono::duration<double>(kinematics::kImuHeadingStaleAfter).count());
  }
}

std::string BaseDevice::commandTwist(const TwistCommand& command) {
  // Accepted now: noted before the e-stop check, so an e-stop from here on voids it.
  const BaseController::Generation accepted = controller_.generation();
  // Counted with the other refused commands; the controller ignores it (and counts it) itself.
  if (e_stop_) e_stop_->refuse("cmd_vel");
  char text[160];
  switch (controller_.submitCommand(command.linear_x, command.angular_z, accepted)) {
    case CommandOutcome::kNotFinite:
      inputRefusals().refused("cmd_vel");
      std::snprintf(text, sizeof text,
                    "cmd_vel rejected: linear.x=%f angular.z=%f is not finite; commanding zero "
                    "speed",
                    command.linear_x, command.angular_z);
      if (refused_log_.pass()) log(LogLevel::kWarn, "%s", text);
      return text;
    case CommandOutcome::kVoided:
      std::snprintf(text, sizeof text,
                    "cmd_vel ignored: e-stop engaged after this command was accepted");
      if (voided_log_.pass()) log(LogLevel::kWarn, "%s", text);
      return text;
    case CommandOutcome::kEStopEngaged:
      return "cmd_vel ignored: e_stop is engaged";
    case CommandOutcome::kSent:
    case CommandOutcome::kStored:
      break;
  }
  return {};
}

core::Outcome BaseDevice::reset() {
  if (!controller_.sendReset()) {
    return {false, "base port " + link_.options().path + " is not connected"};
  }
  return {true, "Reset sent"};
}

core::Outcome BaseDevice::clearEncoders() {
  if (!controller_.sendClearEncoders()) {
    return {false, "base port " + link_.options().path + " is not connected"};
  }
  // The AP1 reports no encoder counts, so clearing them changes nothing the driver publishes.
  return {true,
          "clear-encoders sent (the node never reads encoder counts; odom is not affected: use "
          "base/reset_odometry)"};
}

core::Outcome BaseDevice::resetOdometry() {
  controller_.resetOdometry();
  return {true, "odometry pose reset to zero"};
}

void BaseDevice::attachEStop(core::EStop& e_stop) {
  e_stop_ = &e_stop;
  e_stop.addListener([this](bool engaged) { controller_.setEStop(engaged); });
}

void BaseDevice::retune(const BaseParams& tuned) {
  controller_.retune(tuned.controller);
  std::atomic_store(&tuned_, std::make_shared<const BaseParams>(tuned));
}

void BaseDevice::retune(const params::DriverParams& in_force) {
  retune(in_force.section(kBaseSection));
}

core::StatusReport BaseDevice::status() {
  const std::shared_ptr<const BaseParams> limits = tuned();
  return baseStatus(controller_.stats(), {link_.options().path, link_.connected()},
                    {limits->battery_warn_percent, limits->battery_error_percent});
}

void BaseDevice::useCapabilities(const core::Capabilities& capabilities) {
  // Connected whenever a heading is measured: ~base/use_imu_heading can be switched on at runtime.
  core::HeadingSource* heading = capabilities.find<core::HeadingSource>();
  if (!heading) return;
  controller_.setImuYawVariance(heading->yawVariance());
  heading->addHeadingListener([this](double yaw, core::Clock::time_point arrival) {
    // A replay's arrival times are the recording's; the base loop runs on this machine's clock.
    controller_.onImuYaw(yaw, replaying_ ? core::Clock::now() : arrival);
  });
}

std::string BaseDevice::startupSummary() const {
  std::ostringstream text;
  text << "loop " << loop_rate_ << " Hz, battery poll " << params_.controller.battery_poll_rate
       << " Hz";
  return text.str();
}

}  // namespace serial_robot_driver::devices::base
