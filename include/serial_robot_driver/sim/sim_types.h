// Vocabulary shared by the simulated devices: a steady clock, the frames a device wants sent and
// the world the devices share.
//
// Each simulated device is a plain state machine without I/O or threads: RobotSim feeds it verified
// frames and the current time, and collects the frames it emits. That keeps every device testable
// on its own and lets RobotSim own the ports, the fault injection and the send counters.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "serial_robot_driver/core/clock.h"

namespace serial_robot_driver::sim {

using core::Clock;
using core::fromSeconds;
using core::toSeconds;
using TimePoint = Clock::time_point;

/// A kind of frame a device sends, as RobotSim's fault injection and send counters see it. Each
/// device defines its own (one object per kind: it is known by its address).
struct OutputKind {
  /// Its send counters' stats keys: "<name>_sent_intact", "<name>_sent_damaged", ...
  const char* name;
  /// --corrupt-rate inverts the byte this far from the frame's end (1: the last byte), where the
  /// frame's checksum is; a frame shorter than that has its last byte inverted.
  std::size_t checksum_from_end = 1;
};

struct Outgoing {
  const OutputKind* kind = nullptr;  ///< required: every frame is of a kind its device defines
  std::vector<uint8_t> bytes;
  /// When the device starts sending it (a paced line carries it from then on); {}: now.
  TimePoint ready_at{};
  /// The device's own line fault: the probability RobotSim garbles this frame (half the time) or
  /// does not send it at all (the other half). 0 for most frames.
  double garble_or_suppress_rate = 0.0;
};

/// Frames a device emits during one call, in order.
using Outbox = std::vector<Outgoing>;

/// How the chassis the devices are mounted on moves (zero when no device moves it).
struct ChassisMotion {
  double yaw_rad = 0.0;   ///< heading, counter-clockwise
  double yaw_rate = 0.0;  ///< rad/s
};

/// What the simulated devices share besides their ports, owned by RobotSim and handed to every
/// device's tick: a device that moves the chassis writes it, a device riding on it reads it.
/// Devices tick in the order of cmake/devices.cmake, so a reader after the writer sees this tick's
/// motion.
struct SimWorld {
  ChassisMotion chassis;
};

}  // namespace serial_robot_driver::sim
