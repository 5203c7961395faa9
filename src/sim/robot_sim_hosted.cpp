// RobotSim hosting registered devices it does not know by name (sim/sim_device_module.h): each
// on its own link or the shared one, fed the frames of its simulator families.
#include <algorithm>
#include <random>
#include <stdexcept>

#include "robot_sim_port.h"
#include "serial_robot_driver/device/device_module.h"

namespace serial_robot_driver::sim {

using detail::kMaxBacklogBytes;

void RobotSim::startHosted(TimePoint now) {
  uint32_t seed = options_.faults.seed + 10;
  for (const HostedDeviceOptions& options : options_.hosted) {
    const SimDeviceModule* module = findSimDevice(options.name);
    const device::DeviceModule* core = device::findDevice(options.name);
    if (module == nullptr || module->make == nullptr || core == nullptr) {
      throw std::invalid_argument("robot_sim: no registered device '" + options.name + "' to host");
    }
    const bool twice = std::any_of(hosted_.begin(), hosted_.end(),
                                   [&](const Hosted& other) { return other.name == options.name; });
    if (twice) throw std::invalid_argument("robot_sim: " + options.name + " is hosted twice");
    Hosted hosted;
    hosted.name = options.name;
    hosted.families = core->simulator_frames;
    hosted.device = module->make(options, seed++, now);
    hosted.port_link = options.link.value_or(options_.link);
    hosted_.push_back(std::move(hosted));
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
    HostedOutbox outbox;
    hosted.device->handleFrame(family, data, size, at, &outbox);
    sendHosted(port, &outbox);
    return true;
  }
  return false;
}

void RobotSim::sendHosted(Port* port, HostedOutbox* outbox) {
  const FaultOptions& faults = options_.faults;
  std::uniform_real_distribution<double> chance(0.0, 1.0);
  for (std::vector<uint8_t>& bytes : *outbox) {
    if (bytes.empty()) continue;
    if (port == nullptr || !port->plugged || port->draining ||
        port->backlog_bytes + bytes.size() > kMaxBacklogBytes) {
      ++counters_.hosted_frames_discarded;
      continue;
    }
    // The same damage as the built-in devices' frames get: the last byte is taken as the check.
    if (faults.corrupt_rate > 0 && chance(port->rng) < faults.corrupt_rate) bytes.back() ^= 0xFF;
    if (faults.drop_rate > 0 && chance(port->rng) < faults.drop_rate) {
      const std::size_t index =
          std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(port->rng);
      bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(index));
    }
    port->backlog_bytes += bytes.size();
    // Not a built-in kind: counted by the device itself, so not in the per-kind send counters.
    Port::PendingWrite write;
    write.bytes = std::move(bytes);
    write.is_frame = false;
    write.ready_at = Clock::now();
    port->backlog.push_back(std::move(write));
  }
  outbox->clear();
  if (port != nullptr) flush(port);
}

}  // namespace serial_robot_driver::sim
