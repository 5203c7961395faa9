#include "robot_sim_hosted.h"

#include <algorithm>
#include <stdexcept>

#include "serial_robot_driver/core/device_module.h"

namespace serial_robot_driver::sim::detail {

HostedDevices::HostedDevices(SimOptions& options, SimStats& counters, Line& line)
    : options_(options), counters_(counters), line_(line) {}

void HostedDevices::start(TimePoint now) {
  for (const SimDeviceModule* module : registeredSimDevices()) {
    if (!options_.hosts(module->name)) {
      // Left out: a device that keeps its stats keys keeps its send counters too, at zero.
      if (module->left_out_stats != nullptr) {
        for (const OutputKind* kind : module->outputs) sendCounters(counters_, kind);
      }
      continue;
    }
    const core::DeviceModule* core = core::findDevice(module->name);
    if (module->make == nullptr || core == nullptr) {
      throw std::invalid_argument(std::string("robot_sim: no registered device '") + module->name +
                                  "' to host");
    }
    // A device nobody set anything for is hosted with its defaults.
    const HostedDeviceOptions* given = options_.findDevice(module->name);
    const HostedDeviceOptions options = given ? *given : options_.device(module->name);
    Hosted hosted;
    hosted.name = module->name;
    hosted.families = core->simulator_frames;
    hosted.device = module->make(options, options_.faults.seed + module->seed_offset, now);
    hosted.port_link = options.link.value_or(options_.link);
    hosted_.push_back(std::move(hosted));
    for (const OutputKind* kind : module->outputs) sendCounters(counters_, kind);
  }
}

bool HostedDevices::deliver(Port* port, const protocol::FrameFamily& family, const uint8_t* data,
                            std::size_t size, TimePoint at) {
  for (Hosted& hosted : hosted_) {
    if (hosted.port != port) continue;
    if (std::find(hosted.families.begin(), hosted.families.end(), family) ==
        hosted.families.end()) {
      continue;
    }
    hosted.device->handleFrame(family, data, size, at, &hosted.outbox);
    sendAll(&hosted);
    return true;
  }
  return false;
}

void HostedDevices::tick(TimePoint now) {
  // Every device ticks before any sends: what one writes into the world (the chassis it moves)
  // reaches a later one in the same step.
  for (Hosted& hosted : hosted_) hosted.device->tick(now, world_, &hosted.outbox);
  for (Hosted& hosted : hosted_) sendAll(&hosted);
}

TimePoint HostedDevices::nextEvent() const {
  TimePoint next = TimePoint::max();
  for (const Hosted& hosted : hosted_) next = std::min(next, hosted.device->nextEvent());
  return next;
}

void HostedDevices::addStats(SimStats* stats) const {
  for (const SimDeviceModule* module : registeredSimDevices()) {
    PortCounters seen;
    seen.all_ports = stats->framer;
    const auto hosted = std::find_if(hosted_.begin(), hosted_.end(),
                                     [&](const Hosted& h) { return h.name == module->name; });
    if (hosted != hosted_.end()) {
      seen.own_port = hosted->port->framer->stats();
      stats->devices.push_back(hosted->device->stats(seen));
    } else if (module->left_out_stats != nullptr) {
      stats->devices.push_back(module->left_out_stats(seen));  // its keys, at zero
    }
  }
}

void HostedDevices::sendAll(Hosted* hosted) {
  for (Outgoing& frame : hosted->outbox) line_.send(hosted->port, std::move(frame));
  hosted->outbox.clear();
}

}  // namespace serial_robot_driver::sim::detail
