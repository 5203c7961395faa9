// RobotSim hosting the registered devices (sim/sim_device_module.h): each on its own link or the
// shared one, fed the frames of its simulator families, its frames sent with its send counters.
#include <algorithm>
#include <stdexcept>

#include "robot_sim_port.h"
#include "serial_robot_driver/device/device_module.h"

namespace serial_robot_driver::sim {

void RobotSim::startHosted(TimePoint now) {
  for (const SimDeviceModule* module : registeredSimDevices()) {
    if (!options_.hosts(module->name)) {
      // Left out: a device that keeps its stats keys keeps its send counters too, at zero.
      if (module->left_out_stats != nullptr) {
        for (const OutputKind* kind : module->outputs) countersOf(kind);
      }
      continue;
    }
    const device::DeviceModule* core = device::findDevice(module->name);
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
    for (const OutputKind* kind : module->outputs) countersOf(kind);
  }
}

bool RobotSim::deliverToHosted(Port* port, const protocol::FrameFamily& family, const uint8_t* data,
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

void RobotSim::sendAll(Hosted* hosted) {
  for (Outgoing& frame : hosted->outbox) send(hosted->port, std::move(frame));
  hosted->outbox.clear();
}

SendCounters& RobotSim::countersOf(const OutputKind* kind) {
  for (auto& [sent_kind, counters] : counters_.sent) {
    if (sent_kind == kind) return counters;
  }
  return counters_.sent.emplace_back(kind, SendCounters{}).second;
}

}  // namespace serial_robot_driver::sim
