// A pseudo-terminal pair for the simulator, the tests and the benchmarks (part of srd_sim, not of
// the driver's core): the master side plays the robot, the slave path is what the driver opens
// like a serial port. Closing the master makes the driver's
// reads fail with EIO, which is how an unplugged adapter looks.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

namespace serial_robot_driver::sim {

/// Threading: one thread may read while another writes; close() must not race with them.
class PseudoTerminal {
 public:
  /// Opens a pty in raw mode. If `link_path` is not empty, a symlink to the slave is (re)created
  /// there (replacing a stale symlink, never a regular file) and removed again on close.
  /// \throws transport::TransportError kOpenFailed on failure.
  explicit PseudoTerminal(const std::string& link_path = "");
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  int masterFd() const { return master_fd_; }
  const std::string& slavePath() const { return slave_path_; }
  const std::string& linkPath() const { return link_path_; }

  /// Waits up to `timeout_ms` and reads what the driver wrote (0 on timeout).
  /// \throws transport::TransportError as SerialPort::read.
  std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms);
  /// \throws transport::TransportError as SerialPort::write.
  void write(const uint8_t* data, std::size_t size);
  /// Closes both sides and removes the symlink (a simulated unplug). Idempotent.
  void close();
  bool isOpen() const { return master_fd_ >= 0; }

 private:
  std::atomic<int> master_fd_{-1};
  int slave_fd_ = -1;  ///< kept open so the master never sees a hang-up while no client is attached
  std::string slave_path_;
  std::string link_path_;
};

}  // namespace serial_robot_driver::sim
