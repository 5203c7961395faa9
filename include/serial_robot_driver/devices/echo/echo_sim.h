// The simulated echo device: answers every request with its payload, after an optional latency.
// Hosted by robot_sim through the registry (sim/sim_device_module.h): robot_sim --echo.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::sim {

/// Its answers: an XOR checksum in the last byte.
extern const OutputKind kEchoAnswerOutput;

struct EchoSimStats {
  uint64_t requests = 0;
  uint64_t answers = 0;
};

class EchoSim : public SimDevice {
 public:
  explicit EchoSim(Clock::duration latency) : latency_(latency) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   TimePoint at, Outbox* out) override;
  /// Sends the answers whose latency is over.
  void tick(TimePoint now, SimWorld& world, Outbox* out) override;
  TimePoint nextEvent() const override;
  DeviceSimStats stats(const PortCounters& ports) const override;

  const EchoSimStats& stats() const { return stats_; }

 private:
  Clock::duration latency_;
  std::deque<std::pair<TimePoint, std::vector<uint8_t>>> pending_;  ///< answers and when due
  EchoSimStats stats_;
};

}  // namespace serial_robot_driver::sim
