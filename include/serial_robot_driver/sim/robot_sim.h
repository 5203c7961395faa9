// The simulated robot: every registered device it is asked to host (sim/sim_device_module.h; by
// default the robot's own) on one or more pseudo-terminals, speaking the real bytes, with optional
// fault injection. ROS-free; `robot_sim` is a thin main around it (its flags: command_line.h) and
// tests run it in-process.
//
// Threading: start() spawns one thread that owns the ptys and the devices. It polls the pty master
// fds, feeds each port's StreamFramer, runs the device timers on the steady clock and writes the
// emitted frames (non-blocking; whole frames are dropped, never split, when nobody reads the
// slave), no faster than --pace-baud allows when it is set. stats() and ports() may be called from
// any thread; they take a snapshot under a mutex.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/sim/sim_device_module.h"
#include "serial_robot_driver/sim/sim_options.h"
#include "serial_robot_driver/sim/sim_stats.h"

namespace serial_robot_driver::sim {

namespace detail {  // RobotSim's parts (src/sim/robot_sim_*.h)
struct Port;
class Line;
class HostedDevices;
class PlugFaults;
}  // namespace detail

/// One pty (or, for a tcp:// link, one listening socket) and the devices on it.
struct SimPort {
  std::vector<std::string> devices;  ///< the hosted devices' names
  std::string link;                  ///< "" when none
  /// Changes after a replug; for a tcp:// link the URL listened on, its port as bound (a link
  /// with port 0 gets one from the kernel).
  std::string slave_path;
  bool plugged = true;
};

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
  /// The fds one wait polls: the wake pipe first, then the ports it reads or writes.
  struct PollSet;

  void checkSomethingHosted() const;
  /// The port of `link`, made (with its framer feeding the hosted devices) on first use.
  detail::Port* portFor(const std::string& link, const std::string& device_name);
  /// Opens the port's pty and schedules its faults.
  void openPort(detail::Port* port, TimePoint now);
  void run();
  /// The ports to poll now (mutex_ held while it reads them).
  void preparePoll(PollSet* poll);
  /// Reads what the host wrote on every port the poll found readable (and takes a TCP port's
  /// waiting client).
  void readPorts(const PollSet& poll);
  /// A TCP port's client connected / closed its connection.
  void attachClient(detail::Port* port);
  void detachClient(detail::Port* port);
  void step(TimePoint now);
  /// The first of every device's, line's and fault's next event (a wake-up at least every 100 ms).
  TimePoint nextWakeUp(TimePoint now) const;
  void writeStatsFile() const;
  SimStats snapshotLocked() const;
  void event(const std::string& text) const;

  SimOptions options_;
  mutable std::mutex mutex_;  ///< guards everything below except running_/stop_requested_
  std::vector<std::unique_ptr<detail::Port>> ports_;
  SimStats counters_;  ///< the RobotSim-level fields and send counters; devices keep their own
  std::unique_ptr<detail::Line> line_;
  std::unique_ptr<detail::HostedDevices> hosted_;
  std::unique_ptr<detail::PlugFaults> plug_faults_;
  TimePoint started_at_;
  TimePoint next_stats_write_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  int wake_pipe_[2] = {-1, -1};
};

}  // namespace serial_robot_driver::sim
