// RobotSim hosting the registered devices (sim/sim_device_module.h): each on its own link or the
// shared one, fed the frames of its simulator families, its frames sent with its send counters.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "robot_sim_line.h"
#include "robot_sim_port.h"
#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::sim::detail {

/// A registered device hosted through its SimDeviceModule, on its port.
struct Hosted {
  std::string name;
  std::vector<protocol::FrameFamily> families;  ///< what it reads (simulator_frames)
  std::unique_ptr<SimDevice> device;
  std::string port_link;  ///< its effective link
  Port* port = nullptr;
  Outbox outbox;  ///< what it emitted in this step, not yet sent
};

/// The devices SimOptions hosts, in the order of the devices, and the world they share.
class HostedDevices {
 public:
  /// All three must outlive it (RobotSim's own); the devices' frames go out through `line`.
  HostedDevices(SimOptions& options, SimStats& counters, Line& line);

  /// Builds every device SimOptions hosts and its send counters. Throws std::invalid_argument for
  /// a device without a simulator or a core module.
  void start(TimePoint now);
  /// Every hosted device, to place on its port.
  std::vector<Hosted>& all() { return hosted_; }
  /// Hands a frame to the hosted device on `port` that reads `family`; false when none does.
  bool deliver(Port* port, const protocol::FrameFamily& family, const uint8_t* data,
               std::size_t size, TimePoint at);
  /// Runs every device's timers, then sends what they emitted.
  void tick(TimePoint now);
  /// The earliest of the devices' next events.
  TimePoint nextEvent() const;
  /// Every registered device's stats (zero for one left out that keeps its keys), given the
  /// framers' sum in stats->framer.
  void addStats(SimStats* stats) const;

 private:
  /// Writes what `hosted` emitted on its port, in order.
  void sendAll(Hosted* hosted);

  SimOptions& options_;  ///< device() makes a device's defaults on first use
  SimStats& counters_;
  Line& line_;
  std::vector<Hosted> hosted_;
  SimWorld world_;  ///< what the devices share (the chassis), handed to each tick
};

}  // namespace serial_robot_driver::sim::detail
