// RobotSim's --unplug-every fault: a port's pty closes (its link disappears) and comes back.
#include <fcntl.h>
#include <unistd.h>

#include "robot_sim_port.h"
#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::sim {

using detail::joinNames;
using detail::setNonBlocking;

namespace {
constexpr auto kReplugRetry = std::chrono::seconds(1);
}  // namespace

void RobotSim::unplug(Port* port, TimePoint now) {
  for (const Port::PendingWrite& pending : port->backlog) {
    if (pending.is_frame) ++countersOf(pending.kind).discarded;
  }
  port->backlog.clear();
  port->backlog_bytes = 0;
  port->rx_in_flight.clear();
  if (port->drain_probe_fd >= 0) {
    ::close(port->drain_probe_fd);
    port->drain_probe_fd = -1;
  }
  port->pty->close();  // closes both sides and removes the symlink
  port->pty.reset();
  port->draining = false;
  port->plugged = false;
  port->replug_at = now + fromSeconds(options_.faults.unplug_duration_s);
  ++counters_.unplugs;
  event("robot_sim: " + joinNames(port->device_names) + " unplugged" +
        (port->link.empty() ? "" : " (link " + port->link + ")"));
}

void RobotSim::replug(Port* port, TimePoint now) {
  try {
    port->pty = std::make_unique<PseudoTerminal>(port->link);
  } catch (const transport::TransportError& error) {
    port->replug_at = now + kReplugRetry;
    event(std::string("robot_sim: replug failed, retrying: ") + error.what());
    return;
  }
  port->slave_path = port->pty->slavePath();
  setNonBlocking(port->pty->masterFd());
  port->framer->reset();  // a partial frame from before the unplug is meaningless now
  port->plugged = true;
  port->replug_at = TimePoint::max();
  port->next_unplug = now + fromSeconds(options_.faults.unplug_every_s);
  ++counters_.replugs;
  event("robot_sim: " + joinNames(port->device_names) + " on " + port->slave_path +
        (port->link.empty() ? "" : " (link " + port->link + ")"));
}

}  // namespace serial_robot_driver::sim
