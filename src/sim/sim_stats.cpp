#include "serial_robot_driver/sim/sim_stats.h"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace serial_robot_driver::sim {

using protocol::FrameFamily;

std::string formatStats(const SimStats& stats) {
  std::ostringstream out;
  const auto line = [&out](const std::string& key, auto value) {
    out << key << ' ' << value << '\n';
  };
  out << std::fixed << std::setprecision(3);
  line("uptime_s", stats.uptime_s);

  const BaseSimStats& base = stats.base;
  line("base_frames_received", base.frames_received);
  line("base_seq_gaps", base.seq_gaps);
  line("base_resets", base.resets);
  line("base_speed_frames_applied", base.speed_frames_applied);
  line("base_speed_frames_ignored", base.speed_frames_ignored);
  line("base_errors_sent", base.errors_sent);
  line("base_timeouts", base.timeouts);
  line("base_battery_requests", base.battery_requests);
  line("base_encoder_clears", base.encoder_clears);
  line("base_unknown_frames", base.unknown_frames);
  line("base_in_error", base.in_error ? 1 : 0);
  line("left_ticks", base.left_ticks);
  line("right_ticks", base.right_ticks);
  line("base_x_m", base.x_m);
  line("base_y_m", base.y_m);
  line("base_yaw_rad", base.yaw_rad);
  line("last_left_speed", base.last_left_speed);
  line("last_right_speed", base.last_right_speed);

  const BodySimStats& body = stats.body;
  line("telemetry_generated", body.telemetry_generated);
  line("telemetry_with_foot", body.telemetry_with_foot);
  line("sync_writes_ok", body.sync_writes_ok);
  line("sync_writes_bad", body.sync_writes_malformed + stats.body_port_checksum_errors);
  line("sync_write_unknown_ids", body.sync_write_unknown_ids);
  line("yaw_rad", body.yaw_rad);
  for (const BodySimServoState& servo : body.servos) {
    const std::string prefix = "servo_" + std::to_string(servo.id);
    line(prefix + "_position", std::lround(servo.position));
    line(prefix + "_target", servo.target);
    line(prefix + "_speed", servo.speed);
  }

  const ServoBusSimStats& bus = stats.servo_bus;
  line("servo_requests", bus.requests);
  line("servo_answers", bus.answers);
  line("servo_broadcasts", bus.broadcasts);
  line("servo_unaddressed", bus.unaddressed);
  line("servo_unknown_data_ids", bus.unknown_data_ids);
  line("servo_malformed", bus.malformed);
  line("servo_writes_rejected", bus.writes_rejected);
  line("servo_stops_lost", bus.stops_lost);
  for (const BusServoSnapshot& servo : bus.servos) {
    line("bus_servo_" + std::to_string(servo.id) + "_angle_deg", servo.angle_deg);
  }

  static const char* const kKindNames[kOutputKindCount] = {"base_replies", "telemetry",
                                                           "servo_answers"};
  for (std::size_t k = 0; k < kOutputKindCount; ++k) {
    const std::string name = kKindNames[k];
    line(name + "_sent_intact", stats.sent[k].intact);
    line(name + "_sent_damaged", stats.sent[k].damaged);
    line(name + "_suppressed", stats.sent[k].suppressed);
    line(name + "_discarded", stats.sent[k].discarded);
  }

  line("rx_bytes", stats.bytes_received);
  line("rx_bytes_skipped", stats.framer.bytes_skipped);
  line("rx_checksum_errors", stats.framer.checksum_errors);
  line("rx_bad_lengths", stats.framer.bad_lengths);
  line("rx_unknown_commands", stats.framer.unknown_commands);
  line("rx_frames_base", stats.framer.framesOf(protocol::base::kFrames));
  line("rx_frames_servo_request", stats.framer.framesOf(protocol::servo::kRequestFrames));
  line("rx_frames_sync_write", stats.framer.framesOf(protocol::body::kSyncWriteFrames));
  line("frames_for_absent_device", stats.frames_for_absent_device);
  line("tx_bytes", stats.bytes_sent);
  line("garbage_bursts", stats.garbage_bursts);
  line("garbage_bytes", stats.garbage_bytes);
  line("unplugs", stats.unplugs);
  line("replugs", stats.replugs);
  // Only with hosted devices, so the built-in robot's stats read as they always did.
  for (const auto& [key, value] : stats.hosted) line(key, value);
  if (!stats.hosted.empty()) line("hosted_frames_discarded", stats.hosted_frames_discarded);
  return out.str();
}

}  // namespace serial_robot_driver::sim
