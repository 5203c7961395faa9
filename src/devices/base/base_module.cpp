// The AP1 wheeled base as a device of the driver: its frames, its parameter section and checks.
#include <cmath>
#include <sstream>

#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/devices/base/base_device.h"
#include "serial_robot_driver/devices/base/base_params.h"
#include "serial_robot_driver/devices/body/body_params.h"
#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::devices::base {
extern const params::SectionKey<BaseParams> kBaseSection{"base"};

BaseConfig makeBaseConfig(const params::DriverParams& params) {
  BaseConfig config = params.section(kBaseSection).controller;
  config.loop_rate = params.loop_rate;
  config.realtime_priority = params.realtime_priority;
  config.scheduler_slice_us = params.scheduler_slice_us;
  config.baud = params.baudOf(*core::findDevice("base"));
  return config;
}
}  // namespace serial_robot_driver::devices::base

namespace serial_robot_driver::devices::base {

namespace {

using params::DriverParams;
using params::require;

void addParameters(std::vector<params::ParamSpec>& table) {
  // Three kinds of rows, in the documented order: the wheel geometry and the controller's other
  // settings (bound into BaseParams::controller), and the ROS layer's own values.
  using Own = BaseParams;
  using Controller = BaseConfig;
  using Geometry = kinematics::DiffDriveGeometry;
  params::SectionRows<Geometry> geometry(table, "base", "base", [](DriverParams& p) -> Geometry& {
    return p.section(kBaseSection).controller.geometry;
  });
  params::SectionRows<Controller> controller(
      table, "base", "base",
      [](DriverParams& p) -> Controller& { return p.section(kBaseSection).controller; });
  params::SectionRows<Own> own(table, "base", "base",
                               [](DriverParams& p) -> Own& { return p.section(kBaseSection); });
  geometry
      .add("wheel_diameter", &Geometry::wheel_diameter, params::positiveNumber)
      // A whole number of ticks, which the geometry's arithmetic keeps as a double.
      .addConverted<int>(
          "encoder_resolution", [](Geometry& g) -> double& { return g.encoder_resolution; },
          [](int ticks) { return static_cast<double>(ticks); },
          [](double ticks) { return static_cast<int>(std::lround(ticks)); },
          params::positiveInteger)
      .add("pid_rate", &Geometry::pid_rate, params::positiveNumber)
      .add("wheel_separation", &Geometry::wheel_separation, params::positiveNumber);
  // > 0: there is no "no limit" value. No maximum: the base's top speed is not documented,
  // and the speed field's own range (int16 ticks per PID period) depends on tunable geometry.
  controller.add("max_wheel_speed", &Controller::max_wheel_speed, params::positiveNumber)
      .add("max_wheel_accel", &Controller::max_wheel_accel, params::nonNegativeNumber)
      .add("cmd_vel_timeout", &Controller::cmd_vel_timeout,
           [](const double& value, const std::string& key) {
             // Bounded: the deadman that stops the base when its client dies is not tuned away.
             params::positiveNumber(value, key);
             params::numberWithin(0.0, Controller::kMaxCmdVelTimeout,
                                  "s (at most: the deadman that stops the base)")(value, key);
           })
      .add("speed_dithering", &Controller::speed_dithering)
      .add("battery_poll_rate", &Controller::battery_poll_rate, params::nonNegativeNumber);
  own.add("battery_warn_percent", &Own::battery_warn_percent, params::percent)
      .add("battery_error_percent", &Own::battery_error_percent, params::percent)
      .add("odom_frame", &Own::odom_frame, params::frameId)
      .add("base_frame", &Own::base_frame, params::frameId)
      .add("publish_tf", &Own::publish_tf);
  controller.add("left_wheel_direction", &Controller::left_wheel_direction, params::direction)
      .add("right_wheel_direction", &Controller::right_wheel_direction, params::direction);
  own.add("left_wheel_joint", &Own::left_wheel_joint, params::frameId)
      .add("right_wheel_joint", &Own::right_wheel_joint, params::frameId);
  controller.add("use_imu_heading", &Controller::use_imu_heading);
}

void validate(const DriverParams& p) {
  const BaseParams& base = p.section(kBaseSection);
  // Every tick's wheel frame is the base's heartbeat; it stops with a timeout error after 1 s
  // without one. 5 Hz leaves five frames in that second, so one lost frame is harmless.
  std::ostringstream rate;
  rate << "must be at least " << kMinBaseLoopRate
       << " Hz while the base is enabled: each loop tick sends the wheel frame that keeps the "
          "base's 1 s heartbeat alive (got "
       << p.loop_rate << ")";
  require(p.loop_rate >= kMinBaseLoopRate, "loop_rate", rate.str());
  require(base.controller.battery_poll_rate <= p.loop_rate, "base/battery_poll_rate",
          "must not exceed loop_rate (requests go out from the loop)");
  require(base.battery_error_percent <= base.battery_warn_percent, "base/battery_error_percent",
          "must not exceed base/battery_warn_percent (" +
              std::to_string(base.battery_warn_percent) + ")");
  require(base.odom_frame != base.base_frame, "base/base_frame",
          "must differ from base/odom_frame ('" + base.odom_frame + "')");
  require(base.left_wheel_joint != base.right_wheel_joint, "base/right_wheel_joint",
          "must differ from base/left_wheel_joint ('" + base.left_wheel_joint + "')");
  if (base.controller.use_imu_heading) {
    require(p.enabled("body"), "base/use_imu_heading",
            "needs the servo controller board's IMU, but body/enabled is false");
    require(
        p.section(body::kImuSection).orientation_variance >= 0, "base/use_imu_heading",
        "needs the IMU's orientation, but imu/orientation_variance is negative (no orientation)");
  }
}

void resolveFrames(DriverParams& p) {
  BaseParams& base = p.section(kBaseSection);
  base.odom_frame = params::resolveFrame(p.tf_prefix, base.odom_frame);
  base.base_frame = params::resolveFrame(p.tf_prefix, base.base_frame);
}

}  // namespace

extern const core::DeviceModule kModule{
    .name = "base",
    .title = "Base",
    .driver_frames = {kFrames},
    .simulator_frames = {kFrames},
    .sections = {&kBaseSection},
    .add_parameters = addParameters,
    .validate = validate,
    .resolve_frames = resolveFrames,
    .make_device = core::makeDevice<BaseDevice>,
};

}  // namespace serial_robot_driver::devices::base
