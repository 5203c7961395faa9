// RobotSim's private parts shared by its classes (robot_sim.cpp, robot_sim_line.cpp,
// robot_sim_plug.cpp, robot_sim_hosted.cpp): one pty with its framer, backlog and fault timers.
#pragma once

#include <fcntl.h>

#include <deque>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/sim/robot_sim.h"

namespace serial_robot_driver::sim {

namespace detail {

/// Bytes queued for a port nobody reads before whole frames are discarded (frames are never cut).
constexpr std::size_t kMaxBacklogBytes = 16 * 1024;

inline void setNonBlocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL, 0);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
}

inline std::string joinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : ",") + name;
  return joined;
}

/// The send counters of frames of `kind` in `counters` (made at zero on first use).
inline SendCounters& sendCounters(SimStats& counters, const OutputKind* kind) {
  for (auto& [sent_kind, sent] : counters.sent) {
    if (sent_kind == kind) return sent;
  }
  return counters.sent.emplace_back(kind, SendCounters{}).second;
}

struct Port {
  struct PendingWrite {
    std::vector<uint8_t> bytes;
    std::size_t offset = 0;
    bool is_frame = true;  ///< false for garbage bursts
    const OutputKind* kind = nullptr;
    bool damaged = false;
    TimePoint ready_at{};  ///< --pace-baud: the line carries it from then on, not before
  };

  std::string link;
  std::vector<std::string> device_names;
  std::unique_ptr<PseudoTerminal> pty;
  std::string slave_path;
  std::unique_ptr<protocol::StreamFramer> framer;
  std::deque<PendingWrite> backlog;
  std::size_t backlog_bytes = 0;
  /// --pace-baud: when the line is free again for what we send, and for what the host sent.
  TimePoint tx_line_free{};
  TimePoint rx_line_free{};
  /// --pace-baud: bytes the host wrote, each chunk with the time its last bit is through the line.
  std::deque<std::pair<TimePoint, std::vector<uint8_t>>> rx_in_flight;
  /// --pace-baud: when the chunk being fed to the framer had its last bit through the line ({}:
  /// not paced, now).
  TimePoint rx_frame_end{};
  bool plugged = true;
  bool draining = false;
  int drain_probe_fd = -1;  ///< our own handle on the slave, to see whether the host read it all
  TimePoint drain_deadline;
  TimePoint next_unplug = TimePoint::max();
  TimePoint replug_at = TimePoint::max();
  TimePoint next_garbage = TimePoint::max();
  std::mt19937 rng;
};

}  // namespace detail

}  // namespace serial_robot_driver::sim
