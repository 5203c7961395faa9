#include "robot_sim_plug.h"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>

#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::sim::detail {

namespace {
/// How long an unplug waits for the host to read what was already sent.
constexpr auto kDrainTimeout = std::chrono::milliseconds(250);
/// While draining, how often the port checks whether the host has read it all.
constexpr auto kDrainPoll = std::chrono::milliseconds(5);
constexpr auto kReplugRetry = std::chrono::seconds(1);

std::string linkSuffix(const Port& port) {
  return port.link.empty() ? "" : " (link " + port.link + ")";
}
}  // namespace

PlugFaults::PlugFaults(const SimOptions& options, SimStats& counters, EventSink event)
    : options_(options), counters_(counters), event_(std::move(event)) {}

void PlugFaults::schedule(Port* port, TimePoint now) {
  if (options_.faults.unplug_every_s > 0) {
    port->next_unplug = now + fromSeconds(options_.faults.unplug_every_s);
  }
}

void PlugFaults::step(Port* port, TimePoint now) {
  if (port->plugged && !port->draining && now >= port->next_unplug) beginDrain(port, now);
  if (port->draining && (drained(*port) || now >= port->drain_deadline)) unplug(port, now);
  if (!port->plugged && now >= port->replug_at) replug(port, now);
}

TimePoint PlugFaults::nextEvent(const Port& port, TimePoint now) const {
  TimePoint next = std::min(port.next_unplug, port.replug_at);
  if (port.draining) next = std::min(next, now + kDrainPoll);
  return next;
}

void PlugFaults::beginDrain(Port* port, TimePoint now) {
  // Let the host read what is already in flight, so "sent" means "could be received".
  port->draining = true;
  port->next_unplug = TimePoint::max();  // replug() schedules the next one
  port->drain_deadline = now + kDrainTimeout;
  if (port->pty)
    port->drain_probe_fd = ::open(port->slave_path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
}

bool PlugFaults::drained(const Port& port) {
  if (port.tcp) return port.backlog.empty() && port.tcp->allSent();
  int unread = 0;
  const bool probe_ok =
      port.drain_probe_fd >= 0 && ::ioctl(port.drain_probe_fd, FIONREAD, &unread) == 0;
  return port.backlog.empty() && probe_ok && unread == 0;
}

void PlugFaults::unplug(Port* port, TimePoint now) {
  discardBacklog(port, counters_);
  if (port->drain_probe_fd >= 0) {
    ::close(port->drain_probe_fd);
    port->drain_probe_fd = -1;
  }
  if (port->pty) port->pty->close();  // closes both sides and removes the symlink
  port->pty.reset();
  port->tcp.reset();  // the client reads EOF, new ones are refused until the replug
  port->draining = false;
  port->plugged = false;
  port->replug_at = now + fromSeconds(options_.faults.unplug_duration_s);
  ++counters_.unplugs;
  event_("robot_sim: " + joinNames(port->device_names) + " unplugged" + linkSuffix(*port));
}

void PlugFaults::replug(Port* port, TimePoint now) {
  try {
    openEndpoint(port);
  } catch (const transport::TransportError& error) {
    port->replug_at = now + kReplugRetry;
    event_(std::string("robot_sim: replug failed, retrying: ") + error.what());
    return;
  }
  port->framer->reset();  // a partial frame from before the unplug is meaningless now
  port->plugged = true;
  port->replug_at = TimePoint::max();
  port->next_unplug = now + fromSeconds(options_.faults.unplug_every_s);
  ++counters_.replugs;
  event_("robot_sim: " + joinNames(port->device_names) + " on " + port->slave_path +
         linkSuffix(*port));
}

}  // namespace serial_robot_driver::sim::detail
