// ROS-free tap between the node under test and a device played elsewhere (e.g. sim::RobotSim in the
// test's process): the node opens the tap's pty, the tap forwards every byte both ways and records
// the verified frames the node wrote, so a test sees the exact frames on the wire while the
// simulator answers them.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/protocol/stream_framer.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/pty_frame_reader.h"

namespace test_support {

class PtyTap {
 public:
  using Clock = std::chrono::steady_clock;
  using Bytes = std::vector<uint8_t>;

  /// One verified frame the node wrote.
  struct Frame {
    serial_robot_driver::protocol::FrameFamily family;
    Bytes bytes;
    Clock::time_point arrival;
  };

  /// Creates a pty whose slave is linked at `node_link` (what the node opens) and opens
  /// `device_path` (the device's side, e.g. the simulator's link) in raw mode. `framer` chooses the
  /// frame families recorded. Throws std::runtime_error when `device_path` cannot be opened.
  PtyTap(const std::string& node_link, const std::string& device_path,
         const serial_robot_driver::protocol::FramerConfig& framer);
  /// Stops the threads and closes both sides.
  ~PtyTap();
  PtyTap(const PtyTap&) = delete;
  PtyTap& operator=(const PtyTap&) = delete;

  /// The frames the node wrote so far, in arrival order.
  std::vector<Frame> frames() const;
  std::size_t frameCount() const;
  /// Waits until `done` holds for the frames recorded so far.
  bool waitForFrames(const std::function<bool(const std::vector<Frame>&)>& done,
                     double timeout_s) const;

 private:
  void forwardFromDevice();

  int device_fd_ = -1;
  serial_robot_driver::sim::PseudoTerminal node_pty_;
  mutable std::mutex mutex_;
  std::vector<Frame> frames_;
  std::atomic<bool> stopping_{false};
  std::thread device_thread_;
  std::unique_ptr<PtyFrameReader> reader_;  // last: stopped first
};

}  // namespace test_support
