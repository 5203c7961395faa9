// The simulated robot's counters: the devices' own and those of the ports (what was sent, damaged,
// dropped), and their "key value" text for the stats file and the exit summary.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/devices/base/base_sim.h"
#include "serial_robot_driver/devices/body/body_sim.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_sim.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::sim {

/// Counters per kind of emitted frame (OutputKind).
struct SendCounters {
  uint64_t intact = 0;      ///< written whole and undamaged
  uint64_t damaged = 0;     ///< written with a flipped checksum, a missing byte or garbled
  uint64_t suppressed = 0;  ///< not sent on purpose (servo fault "missing answer")
  uint64_t discarded = 0;   ///< not sent: port unplugged or nobody reading (backlog full)
};

struct SimStats {
  BaseSimStats base;
  BodySimStats body;
  ServoBusSimStats servo_bus;
  std::array<SendCounters, kOutputKindCount> sent{};
  protocol::FramerStats framer;  ///< summed over the ports (host -> sim direction)
  uint64_t bytes_received = 0;
  uint64_t bytes_sent = 0;
  /// CRC failures on the body's port: bad sync-writes (on a shared port the framer cannot tell
  /// whose a broken frame was, so bad frames of the other devices count here too).
  uint64_t body_port_checksum_errors = 0;
  uint64_t frames_for_absent_device = 0;  ///< e.g. a sync-write on a port without the body
  uint64_t garbage_bursts = 0;
  uint64_t garbage_bytes = 0;
  uint64_t unplugs = 0;
  uint64_t replugs = 0;
  double uptime_s = 0.0;
  /// The hosted devices' own "key value" lines (SimDevice::statsLines), in hosting order.
  std::vector<std::pair<std::string, std::string>> hosted;
  /// Frames the hosted devices wanted sent but their port could not take (unplugged, full).
  uint64_t hosted_frames_discarded = 0;
};

/// `key value` lines (one per line, stable key names) for the stats file and the exit summary.
std::string formatStats(const SimStats& stats);

}  // namespace serial_robot_driver::sim
