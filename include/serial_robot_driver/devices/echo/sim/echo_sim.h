// The simulated echo device: answers every request with its payload, after an optional latency.
// Hosted by robot_sim through the registry (sim/sim_device_module.h): robot_sim --echo.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::devices::echo::sim {

/// Its answers: an XOR checksum in the last byte.
extern const serial_robot_driver::sim::OutputKind kEchoAnswerOutput;

struct EchoSimStats {
  uint64_t requests = 0;
  uint64_t answers = 0;
};

class EchoSim : public serial_robot_driver::sim::SimDevice {
 public:
  explicit EchoSim(serial_robot_driver::sim::Clock::duration latency) : latency_(latency) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   serial_robot_driver::sim::TimePoint at,
                   serial_robot_driver::sim::Outbox* out) override;
  /// Sends the answers whose latency is over.
  void tick(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::SimWorld& world,
            serial_robot_driver::sim::Outbox* out) override;
  serial_robot_driver::sim::TimePoint nextEvent() const override;
  serial_robot_driver::sim::DeviceSimStats stats(
      const serial_robot_driver::sim::PortCounters& ports) const override;

  const EchoSimStats& stats() const { return stats_; }

 private:
  serial_robot_driver::sim::Clock::duration latency_;
  std::deque<std::pair<serial_robot_driver::sim::TimePoint, std::vector<uint8_t>>>
      pending_;  ///< answers and when due
  EchoSimStats stats_;
};

}  // namespace serial_robot_driver::devices::echo::sim
