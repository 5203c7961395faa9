// The simulated robot's counters: the devices' own and those of the ports (what was sent, damaged,
// dropped), and their "key value" text for the stats file and the exit summary. A device's typed
// counters are read through its own accessor (<name>Stats(stats) in its <name>_sim.h).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/sim_device_module.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::sim {

/// Counters per kind of emitted frame (OutputKind).
struct SendCounters {
  uint64_t intact = 0;      ///< written whole and undamaged
  uint64_t damaged = 0;     ///< written with a flipped checksum, a missing byte or garbled
  uint64_t suppressed = 0;  ///< not sent on purpose (a device's line fault: "missing answer")
  uint64_t discarded = 0;   ///< not sent: port unplugged or nobody reading (backlog full)
};

struct SimStats {
  /// The devices' counters, in the order of the devices: the hosted ones, and those left out
  /// that keep their stats keys (at zero).
  std::vector<DeviceSimStats> devices;
  /// Per kind of frame the hosted devices send, in the order they declare them.
  std::vector<std::pair<const OutputKind*, SendCounters>> sent;
  protocol::FramerStats framer;  ///< summed over the ports (host -> sim direction)
  uint64_t bytes_received = 0;
  uint64_t bytes_sent = 0;
  uint64_t frames_for_absent_device = 0;  ///< a frame on a port where no device reads it
  uint64_t garbage_bursts = 0;
  uint64_t garbage_bytes = 0;
  uint64_t unplugs = 0;
  uint64_t replugs = 0;
  double uptime_s = 0.0;

  /// The send counters of `kind` (zero when no hosted device sends it).
  const SendCounters& sentOf(const OutputKind& kind) const&;
  /// The same of a temporary snapshot (robot.stats().sentOf(kind)): a copy, which outlives it.
  SendCounters sentOf(const OutputKind& kind) && { return std::as_const(*this).sentOf(kind); }
  /// The counters of the device `name`, or null when it is neither hosted nor keeps its keys.
  const DeviceSimStats* findDevice(const std::string& name) const;
  /// The typed counters of the device `name` (all zero when it was not simulated).
  template <typename Counters>
  const Counters& countersOf(const std::string& name) const {
    static const Counters kNotSimulated{};
    const DeviceSimStats* device = findDevice(name);
    if (device == nullptr || device->counters.empty()) return kNotSimulated;
    return device->counters.as<Counters>();
  }
};

/// `key value` lines (one per line, stable key names) for the stats file and the exit summary.
std::string formatStats(const SimStats& stats);

}  // namespace serial_robot_driver::sim
