#include "serial_robot_driver/core/port_log.h"

#include "serial_robot_driver/core/log.h"
#include "serial_robot_driver/transport/tcp_stream.h"

namespace serial_robot_driver::core {

void PortLog::onLinkUp() {
  waiting_logged_ = false;
  const LinkStats stats = link_.stats();
  const char* path = link_.options().path.c_str();
  if (transport::isTcpUrl(link_.options().path)) {
    // No local serial line to configure: the server's settings apply.
    log(LogLevel::kInfo,
        "port %s connected (TCP; the serial server sets the baud, ~baud is unused)", path);
    return;
  }
  log(LogLevel::kInfo, "port %s connected (low latency: %s)", path,
      stats.low_latency ? "yes" : "not supported");
  if (stats.latency_timer_ms && *stats.latency_timer_ms > 1) {
    log(LogLevel::kWarn,
        "port %s: the USB-serial adapter's latency_timer is %d ms, which delays every frame; "
        "set it to 1 ms with a udev rule (see config/99-serial-robot.rules)",
        path, *stats.latency_timer_ms);
  }
}

void PortLog::onLinkDown() {
  const char* path = link_.options().path.c_str();
  if (shutting_down_) {
    log(LogLevel::kDebug, "port %s closed", path);
    return;
  }
  log(LogLevel::kWarn, "port %s lost (%s); reopening every %.1f s", path,
      link_.stats().last_error.c_str(), link_.options().reconnect_interval);
  waiting_logged_ = true;  // the retries that follow need no message of their own
}

void PortLog::onOpenFailed(const std::string& error) {
  if (waiting_logged_ || shutting_down_) return;  // once per outage, not once per retry
  waiting_logged_ = true;
  log(LogLevel::kWarn, "waiting for port %s (%s); retrying every %.1f s",
      link_.options().path.c_str(), error.c_str(), link_.options().reconnect_interval);
}

}  // namespace serial_robot_driver::core
