#include "serial_robot_driver/devices/body/body_status.h"

#include "serial_robot_driver/protocol/decode_result.h"

namespace serial_robot_driver::devices::body {

BodyStatus::Update BodyStatus::update(const BodyStats& stats, const protocol::FramerStats& framer,
                                      const core::PortState& port) {
  Update update;
  core::StatusReport& status = update.report;
  if (!port.connected) {
    status.mergeSummary(core::StatusLevel::kError, "port " + port.path + " not connected");
  } else if (stats.frames_decoded == 0) {
    // ERROR, as the frequency check's "No events recorded." already is: a board streaming
    // nothing is a fault a robot monitor must show red, not a warning.
    status.mergeSummary(core::StatusLevel::kError, "no telemetry received yet");
  } else if (stats.frames_decoded == frames_at_last_period_) {
    status.mergeSummary(core::StatusLevel::kError, "telemetry stopped");
  }

  const bool stalled =
      port.connected && stats.frames_decoded > 0 && stats.frames_decoded == frames_at_last_period_;
  if (stalled && !stop_reported_) {
    update.flow = FlowChange::kStopped;
    stop_reported_ = true;
  } else if (!stalled && stop_reported_ && stats.frames_decoded != frames_at_last_period_) {
    update.flow = FlowChange::kResumed;
    stop_reported_ = false;
  }
  frames_at_last_period_ = stats.frames_decoded;

  status.hardware_id = port.path;
  status.add("port", port.path);
  status.add("connected", port.connected);
  status.add("frames decoded", stats.frames_decoded);
  status.add("decode errors", stats.decode_errors);
  status.add("last decode error",
             stats.last_decode_error ? protocol::toString(*stats.last_decode_error) : "none");
  status.add("commands sent", stats.commands_sent);
  status.add("commands rejected", stats.commands_rejected);
  status.add("joint targets out of range", stats.joints_out_of_range);
  status.add("command write failures", stats.write_failures);
  status.add("commands refused when written (e_stop)", stats.motion_refused);
  status.add("commands voided (e_stop engaged after they were accepted)", stats.motion_voided);
  status.add("port checksum errors", framer.checksum_errors);
  status.add("port bad tails", framer.bad_tails);
  status.add("port bytes skipped (resync)", framer.bytes_skipped);
  return update;
}

}  // namespace serial_robot_driver::devices::body
