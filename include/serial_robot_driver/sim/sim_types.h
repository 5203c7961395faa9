// Vocabulary shared by the simulated devices: a steady clock, and the frames a device wants sent.
//
// Each simulated device is a plain state machine without I/O or threads: RobotSim feeds it verified
// frames and the current time, and collects the frames it emits. That keeps every device testable
// on its own and lets RobotSim own the ports, the fault injection and the send counters.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

namespace serial_robot_driver::sim {

using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;

/// Seconds as a double, for rates and kinematics.
inline double toSeconds(Clock::duration duration) {
  return std::chrono::duration<double>(duration).count();
}
/// A duration from (possibly fractional) seconds.
inline Clock::duration fromSeconds(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

/// What an emitted frame is: RobotSim counts and damages frames per kind.
enum class OutputKind : uint8_t { kBaseReply = 0, kTelemetry, kServoResponse };
constexpr std::size_t kOutputKindCount = 3;

struct Outgoing {
  OutputKind kind = OutputKind::kBaseReply;
  std::vector<uint8_t> bytes;
  /// When the device starts sending it (a paced line carries it from then on); {}: now.
  TimePoint ready_at{};
};

/// Frames a device emits during one call, in order.
using Outbox = std::vector<Outgoing>;

}  // namespace serial_robot_driver::sim
