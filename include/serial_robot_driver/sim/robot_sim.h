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

/// One pty and the devices on it.
struct SimPort {
  std::vector<std::string> devices;  ///< the hosted devices' names
  std::string link;                  ///< "" when none
  std::string slave_path;            ///< changes after a replug
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
  struct Port;
  /// A registered device hosted through its SimDeviceModule, on its port.
  struct Hosted {
    std::string name;
    std::vector<protocol::FrameFamily> families;  ///< what it reads (simulator_frames)
    std::unique_ptr<SimDevice> device;
    std::string port_link;  ///< its effective link
    Port* port = nullptr;
    Outbox outbox;  ///< what it emitted in this step, not yet sent
  };
  /// Builds every device SimOptions hosts, in the order of the devices, and its send counters.
  void startHosted(TimePoint now);
  /// Hands a frame to the hosted device on `port` that reads `family`; false when none does.
  bool deliverToHosted(Port* port, const protocol::FrameFamily& family, const uint8_t* data,
                       std::size_t size, TimePoint at);
  void run();
  void step(TimePoint now);
  /// Writes what `hosted` emitted on its port, in order.
  void sendAll(Hosted* hosted);
  void send(Port* port, Outgoing frame);
  SendCounters& countersOf(const OutputKind* kind);
  void flush(Port* port);
  /// How long the line takes to carry `bytes` at pace_baud (10 bits a byte).
  Clock::duration lineTime(std::size_t bytes) const;
  /// --pace-baud: when flush() has the next bytes of the backlog through the line (max: none).
  TimePoint nextSendAt(const Port* port) const;
  void unplug(Port* port, TimePoint now);
  void replug(Port* port, TimePoint now);
  void writeStatsFile() const;
  SimStats snapshotLocked() const;
  void event(const std::string& text) const;

  SimOptions options_;
  mutable std::mutex mutex_;  ///< guards everything below except running_/stop_requested_
  std::vector<std::unique_ptr<Port>> ports_;
  std::vector<Hosted> hosted_;
  SimWorld world_;     ///< what the devices share (the chassis), handed to each tick
  SimStats counters_;  ///< the RobotSim-level fields and send counters; devices keep their own
  TimePoint started_at_;
  TimePoint next_stats_write_;
  /// --pace-baud: when the frame being fed to a framer had its last bit through the line ({}: now).
  TimePoint rx_frame_end_{};
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stop_requested_{false};
  int wake_pipe_[2] = {-1, -1};
};

}  // namespace serial_robot_driver::sim
