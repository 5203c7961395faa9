// RobotSim's private parts shared by its classes (robot_sim.cpp, robot_sim_line.cpp,
// robot_sim_plug.cpp, robot_sim_hosted.cpp): one pty (or TCP listener) with its framer, backlog and
// fault timers.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <deque>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "robot_sim_tcp.h"
#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "serial_robot_driver/transport/tcp_stream.h"

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
  /// Instead of the pty when the link is a tcp:// URL (a network serial server's stand-in).
  std::unique_ptr<TcpListener> tcp;
  std::string slave_path;  ///< the pty's slave, or the URL the listener is bound to
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

  bool isOpen() const { return pty != nullptr || tcp != nullptr; }
  /// Where the host's bytes come from and the devices' go: the pty master or the TCP client; -1
  /// when there is none (unplugged, or no client connected).
  int dataFd() const {
    if (tcp) return tcp->clientFd();
    return pty && pty->isOpen() ? pty->masterFd() : -1;
  }
  /// Writes what dataFd() takes now, never blocking; -1 and errno as write(2).
  ssize_t writeSome(const uint8_t* data, std::size_t size) const {
    return tcp ? tcp->send(data, size) : ::write(pty->masterFd(), data, size);
  }
};

/// Opens the port's pty at its link, or listens at its tcp:// link (a replug where the first open
/// did: the kernel may have picked the port).
inline void openEndpoint(Port* port) {
  if (transport::isTcpUrl(port->link)) {
    port->tcp =
        std::make_unique<TcpListener>(port->slave_path.empty() ? port->link : port->slave_path);
    port->slave_path = port->tcp->url();
    return;
  }
  port->pty = std::make_unique<PseudoTerminal>(port->link);
  port->slave_path = port->pty->slavePath();
  setNonBlocking(port->pty->masterFd());
}

/// Frames queued for a host that is gone or was not there yet: they never reach anyone.
inline void discardBacklog(Port* port, SimStats& counters) {
  for (const Port::PendingWrite& pending : port->backlog) {
    if (pending.is_frame) ++sendCounters(counters, pending.kind).discarded;
  }
  port->backlog.clear();
  port->backlog_bytes = 0;
  port->rx_in_flight.clear();
}

}  // namespace detail

}  // namespace serial_robot_driver::sim
