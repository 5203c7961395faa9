#include "serial_robot_driver/devices/echo/echo_interface.h"

#include <atomic>
#include <cstdio>

#include "serial_robot_driver/devices/echo/echo_params.h"

namespace serial_robot_driver::ros_layer {

EchoInterface::EchoInterface(ros::NodeHandle& nh, const DriverParams& params,
                             device::SerialLink& link)
    : link_(link),
      controller_(
          link.writer(),
          std::chrono::milliseconds(
              params.sections.get<serial_robot_driver::params::EchoParams>("echo").timeout_ms)) {
  ping_srv_ = nh.advertiseService("echo/ping", &EchoInterface::onPing, this);
  link.addListener(&controller_);
}

void EchoInterface::shutdown() { ping_srv_.shutdown(); }

bool EchoInterface::onPing(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  const device::PingResult result = controller_.ping();
  last_ping_failed_ = !result.ok;
  response.success = result.ok;
  if (result.ok) {
    char text[64];
    std::snprintf(text, sizeof text, "round trip %.3f ms",
                  std::chrono::duration<double, std::milli>(result.round_trip).count());
    response.message = text;
  } else {
    response.message = result.error;
  }
  return true;
}

void EchoInterface::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  const device::EchoStats stats = controller_.stats();
  if (!link_.connected()) {
    status.summary(DiagnosticStatus::ERROR, "port " + link_.options().path + " is not open");
  } else if (last_ping_failed_) {
    status.summary(DiagnosticStatus::WARN, "the last ping had no answer");
  } else if (stats.round_trips == 0) {
    status.summary(DiagnosticStatus::OK, "no ping yet");
  } else {
    status.summary(DiagnosticStatus::OK, "answering");
  }
  status.add("port", link_.options().path);
  status.add("pings", stats.pings);
  status.add("round trips", stats.round_trips);
  status.add("mismatched answers", stats.mismatches);
  status.add("timeouts", stats.timeouts);
  status.add("write failures", stats.write_failures);
  if (stats.last_round_trip) {
    status.addf("last round trip ms", "%.3f",
                std::chrono::duration<double, std::milli>(*stats.last_round_trip).count());
  }
}

}  // namespace serial_robot_driver::ros_layer
