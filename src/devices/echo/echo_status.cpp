#include "serial_robot_driver/devices/echo/echo_status.h"

#include <chrono>

namespace serial_robot_driver::devices::echo {

core::StatusReport echoStatus(const EchoStats& stats, const core::PortState& port) {
  core::StatusReport report;
  report.hardware_id = port.path;
  if (!port.connected) {
    report.summary(core::StatusLevel::kError, "port " + port.path + " is not open");
  } else if (stats.last_ping_failed) {
    report.summary(core::StatusLevel::kWarn, "the last ping had no answer");
  } else if (stats.round_trips == 0) {
    report.summary(core::StatusLevel::kOk, "no ping yet");
  } else {
    report.summary(core::StatusLevel::kOk, "answering");
  }
  report.add("port", port.path);
  report.add("pings", stats.pings);
  report.add("round trips", stats.round_trips);
  report.add("mismatched answers", stats.mismatches);
  report.add("timeouts", stats.timeouts);
  report.add("write failures", stats.write_failures);
  if (stats.last_round_trip) {
    report.addf("last round trip ms", "%.3f",
                std::chrono::duration<double, std::milli>(*stats.last_round_trip).count());
  }
  return report;
}

}  // namespace serial_robot_driver::devices::echo
