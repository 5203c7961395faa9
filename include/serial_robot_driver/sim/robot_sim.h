// The simulated robot: the three devices of PROTOCOLS.md on one or more pseudo-terminals, speaking
// the real bytes, with optional fault injection. ROS-free; `robot_sim` is a thin main around it and
// tests run it in-process.
//
// Threading: start() spawns one thread that owns the ptys and the devices. It polls the pty master
// fds, feeds each port's StreamFramer, runs the device timers on the steady clock and writes the
// emitted frames (non-blocking; whole frames are dropped, never split, when nobody reads the
// slave). stats() and ports() may be called from any thread; they take a snapshot under a mutex.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/base_sim.h"
#include "serial_robot_driver/sim/body_sim.h"
#include "serial_robot_driver/sim/servo_bus_sim.h"

namespace serial_robot_driver::sim {

/// Faults injected into what the simulator sends. All probabilities are per frame, 0..1.
struct FaultOptions {
  uint32_t seed = 1;
  double garbage_rate_hz = 0.0;  ///< junk bursts per second per port (Poisson); any byte values
  double corrupt_rate = 0.0;     ///< a sent frame gets its checksum byte inverted
  double drop_rate = 0.0;        ///< a sent frame loses one random byte
  double unplug_every_s = 0.0;   ///< 0: never unplug
  double unplug_duration_s = 1.0;
  double servo_fault_rate = 0.0;  ///< a servo answer is garbled (half) or not sent (half)
};

struct SimOptions {
  /// Symlink shared by every device without a link of its own ("": no symlink, print the path).
  std::string link;
  /// Per-device links; devices whose effective links are equal share one pty.
  std::optional<std::string> base_link;
  std::optional<std::string> body_link;
  std::optional<std::string> servo_link;
  bool enable_base = true;
  bool enable_body = true;
  bool enable_servo_bus = true;
  BaseSimConfig base;
  BodySimConfig body;
  ServoBusSimConfig servo_bus;
  FaultOptions faults;
  std::string stats_file;  ///< written atomically every stats_period_s and at stop(); "" = none
  double stats_period_s = 1.0;
  /// Human-readable events from the sim thread (unplug, replug with the new pty path).
  std::function<void(const std::string&)> on_event;
};

/// One pty and the devices on it.
struct SimPort {
  std::vector<std::string> devices;  ///< "base", "body", "servo_bus"
  std::string link;                  ///< "" when none
  std::string slave_path;            ///< changes after a replug
  bool plugged = true;
};

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
};

/// `key value` lines (one per line, stable key names) for the stats file and the exit summary.
std::string formatStats(const SimStats& stats);

class RobotSim {
 public:
  explicit RobotSim(SimOptions options);
  ~RobotSim();
  RobotSim(const RobotSim&) = delete;
  RobotSim& operator=(const RobotSim&) = delete;

  /// Creates the ptys (and symlinks) and starts the thread. Throws transport::TransportError when a
  /// pty cannot be created, std::invalid_argument when every device is disabled.
  void start();
  /// Stops the thread and writes the stats file one last time. The ptys stay open until
  /// destruction, so a host can still read what was sent. Idempotent.
  void stop();
  bool running() const { return running_; }

  std::vector<SimPort> ports() const;
  SimStats stats() const;

 private:
  struct Port;
  void run();
  void step(TimePoint now);
  void route(Outgoing frame);  ///< to the port of the device that emitted it
  void send(Port* port, Outgoing frame);
  void flush(Port* port);
  void unplug(Port* port, TimePoint now);
  void replug(Port* port, TimePoint now);
  void writeStatsFile() const;
  SimStats snapshotLocked() const;
  void event(const std::string& text) const;

  SimOptions options_;
  mutable std::mutex mutex_;  ///< guards everything below except running_/stop_requested_
  std::vector<std::unique_ptr<Port>> ports_;
  Port* base_port_ = nullptr;
  Port* body_port_ = nullptr;
  Port* servo_port_ = nullptr;
  std::unique_ptr<BaseSim> base_;
  std::unique_ptr<BodySim> body_;
  std::unique_ptr<ServoBusSim> servo_bus_;
  SimStats counters_;  ///< the RobotSim-level fields only; devices keep their own
  TimePoint started_at_;
  TimePoint next_stats_write_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  int wake_pipe_[2] = {-1, -1};
};

/// Result of parsing the robot_sim command line.
struct CommandLine {
  SimOptions options;
  bool help = false;
  std::string error;  ///< non-empty: print usage on stderr and exit 2
};

/// Parses robot_sim flags. Arguments containing ":=" (roslaunch remappings, __name:=x) are ignored.
CommandLine parseCommandLine(int argc, const char* const* argv);
/// The --help text.
std::string usage();

}  // namespace serial_robot_driver::sim
