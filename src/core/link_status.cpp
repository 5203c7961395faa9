#include "serial_robot_driver/core/link_status.h"

#include <string>

namespace serial_robot_driver::core {

StatusReport linkStatus(const LinkStats& s, const SerialLinkOptions& options) {
  StatusReport status;
  status.hardware_id = options.path;
  if (s.connected) {
    status.summary(StatusLevel::kOk, "connected");
  } else {
    status.summary(StatusLevel::kError,
                   "not connected" + (s.last_error.empty() ? std::string() : ": " + s.last_error));
  }
  status.add("path", options.path);
  status.add("baud", options.baud);
  status.add("connected", s.connected);
  status.add("connects", s.connects);
  status.add("disconnects", s.disconnects);
  status.add("last error", s.last_error);
  status.add("bytes in", s.framer.bytes_in);
  status.add("bytes out", s.bytes_out);
  status.add("frames out", s.frames_out);
  status.add("write failures", s.write_failures);
  for (std::size_t i = 0; i < s.framer.family_count; ++i) {
    if (s.framer.by_family[i].frames == 0) continue;
    status.add(std::string("frames in: ") + s.framer.by_family[i].family,
               s.framer.by_family[i].frames);
  }
  status.add("checksum errors", s.framer.checksum_errors);
  status.add("bad tails", s.framer.bad_tails);
  status.add("bad lengths", s.framer.bad_lengths);
  status.add("unknown servo commands", s.framer.unknown_commands);
  status.add("stale partial frames dropped", s.framer.stale_candidates);
  status.add("bytes skipped (resync)", s.framer.bytes_skipped);
  status.add("internal errors (reader thread)", s.handler_errors);
  status.add("last internal error", s.last_handler_error);
  status.add("low latency", s.low_latency);
  status.add("latency_timer (ms)",
             s.latency_timer_ms ? std::to_string(*s.latency_timer_ms) : std::string("n/a"));
  // Above 1 ms the adapter holds short frames back that long: replies and commands come late.
  if (s.connected && s.latency_timer_ms && *s.latency_timer_ms > 1) {
    status.mergeSummary(StatusLevel::kWarn, "latency_timer above 1 ms");
  }
  // A bug met on the reader thread: the port goes on, but what it dropped is gone.
  if (s.handler_errors > 0) {
    status.mergeSummary(StatusLevel::kWarn,
                        std::to_string(s.handler_errors) + " internal errors on the reader thread");
  }
  return status;
}

}  // namespace serial_robot_driver::core
