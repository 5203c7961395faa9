// The body's diagnostic status ("body"): the link, whether telemetry flows, decode errors, the
// joint commands and the framer's statistics. The telemetry rate itself is a device::EventRate's
// (device/event_rate.h); this report is merged into its verdict.
#pragma once

#include <cstdint>

#include "serial_robot_driver/core/status_report.h"
#include "serial_robot_driver/devices/body/body_controller.h"
#include "serial_robot_driver/protocol/stream_framer.h"

namespace serial_robot_driver::devices::body {

/// Called once per diagnostics period (one thread): a frame count that stood still for a whole
/// period while the port is up means the board stopped talking.
class BodyStatus {
 public:
  /// What the ROS layer logs, once per outage rather than once per period.
  enum class FlowChange { kNone, kStopped, kResumed };
  struct Update {
    /// OK with no message when nothing is wrong (the telemetry rate's verdict stands), else ERROR.
    core::StatusReport report;
    FlowChange flow = FlowChange::kNone;
  };

  Update update(const BodyStats& stats, const protocol::FramerStats& framer,
                const core::PortState& port);

 private:
  uint64_t frames_at_last_period_ = 0;
  bool stop_reported_ = false;
};

}  // namespace serial_robot_driver::devices::body
