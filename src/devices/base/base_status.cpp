#include "serial_robot_driver/devices/base/base_status.h"

#include <string>

namespace serial_robot_driver::devices::base {

namespace {

/// The port down, the base silent, a recent FF timeout error.
void summarizeLink(const BaseStats& s, const core::PortState& port, core::StatusReport* status) {
  if (!port.connected) {
    status->mergeSummary(core::StatusLevel::kError, "port " + port.path + " not connected");
    return;
  }
  if (s.base_silent && s.seconds_without_reply) {
    status->mergeSummaryf(core::StatusLevel::kError, "no reply from the base for %.0f s",
                          *s.seconds_without_reply);
  }
  if (s.seconds_since_running_timeout_error &&
      *s.seconds_since_running_timeout_error < kRecentTimeoutErrorS) {
    status->mergeSummaryf(core::StatusLevel::kWarn,
                          "base reported a timeout error (FF) %.0f s ago: frames were lost",
                          *s.seconds_since_running_timeout_error);
  }
}

void summarizeBattery(const BaseStats& s, BatteryLimits limits, core::StatusReport* status) {
  if (!s.battery_percent) return;
  const int percent = *s.battery_percent;
  if (percent < limits.error_percent) {
    status->mergeSummaryf(core::StatusLevel::kError, "battery %d %% (below %d %%)", percent,
                          limits.error_percent);
  } else if (percent < limits.warn_percent) {
    status->mergeSummaryf(core::StatusLevel::kWarn, "battery %d %% (below %d %%)", percent,
                          limits.warn_percent);
  }
}

void addHeadingSource(const BaseStats& s, core::StatusReport* status) {
  if (!s.heading_source) return;
  // ~base/use_imu_heading: odom without the IMU is worth a warning, the driving goes on.
  if (*s.heading_source != kinematics::HeadingSource::kImu) {
    status->mergeSummaryf(core::StatusLevel::kWarn, "odom heading: %s",
                          kinematics::toString(*s.heading_source));
  }
  status->add("odom heading source", kinematics::toString(*s.heading_source));
  status->add("odom heading IMU fallbacks", s.imu_heading_fallbacks);
  status->add("odom heading IMU yaw age (s)",
              s.imu_yaw_age ? std::to_string(*s.imu_yaw_age) : std::string("none yet"));
}

/// The link's frames and replies, in and out.
void addLinkCounters(const BaseStats& s, const core::PortState& port, core::StatusReport* status) {
  status->add("port", port.path);
  status->add("connected", port.connected);
  status->add("speed frames out", s.speed_frames);
  status->add("immediate frames (new cmd_vel)", s.immediate_frames);
  status->add("e-stop engaged", s.e_stop);
  status->add("cmd_vel ignored (e-stop)", s.ignored_commands_e_stop);
  status->add("cmd_vel voided (e-stop engaged after it was accepted)", s.voided_commands);
  status->add("resets sent", s.resets_sent);
  status->add("FF timeout errors received", s.timeout_errors_received);
  status->add("FF timeout errors while running", s.timeout_errors_while_running);
  if (s.seconds_without_reply) {
    status->addf("seconds without reply", "%.1f", *s.seconds_without_reply);
  }
  status->addf("min immediate frame spacing (ms)", "%.3f", s.min_immediate_interval_ms);
  status->add("battery requests", s.battery_requests);
  status->add("battery replies", s.battery_replies);
  status->add("unknown replies", s.unknown_replies);
  status->add("bad replies", s.bad_replies);
  status->add("write failures", s.write_failures);
}

/// What cmd_vel and the control loop did.
void addLoopCounters(const BaseStats& s, core::StatusReport* status) {
  status->add("cmd_vel timeouts", s.cmd_vel_timeouts);
  status->add("rejected cmd_vel (NaN/Inf)", s.rejected_commands);
  status->add("loop overruns", s.loop_overruns);
  status->add("loop internal errors", s.internal_errors);
  status->add("last loop internal error", s.last_internal_error);
  status->addf("last loop period (ms)", "%.3f", s.last_period_ms);
  status->addf("worst loop period (ms)", "%.3f", s.worst_period_ms);
}

}  // namespace

core::StatusReport baseStatus(const BaseStats& s, const core::PortState& port,
                              BatteryLimits limits) {
  core::StatusReport status;
  status.summary(core::StatusLevel::kOk, "driving");
  summarizeLink(s, port, &status);
  summarizeBattery(s, limits, &status);
  if (s.e_stop) status.mergeSummary(core::StatusLevel::kWarn, "e-stop engaged: holding zero speed");
  if (s.internal_errors > 0) {
    status.mergeSummary(core::StatusLevel::kWarn,
                        std::to_string(s.internal_errors) + " internal errors in the control loop");
  }
  addHeadingSource(s, &status);
  status.hardware_id = port.path;
  addLinkCounters(s, port, &status);
  addLoopCounters(s, &status);
  if (s.battery_percent) status.add("battery (%)", static_cast<int>(*s.battery_percent));
  return status;
}

}  // namespace serial_robot_driver::devices::base
