// The robot's end of the line a benchmark plays the robot on: what it reads the program's frames
// from and writes the robot's frames to. Over a pseudo-terminal the program opens the slave (the
// bytes pass through the kernel's pty worker, flush_to_ldisc on a normal-priority kworker); over
// loopback TCP the program connects as a client (ser2net style, `tcp://127.0.0.1:<port>`) and a
// write() wakes the reader directly, so the figures are the programs' own latency.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace serial_robot_driver::bench {

enum class Transport { kPty, kTcp };

/// "pty" or "tcp".
std::string transportName(Transport transport);

/// Threading: one thread reads while others write (a frame at a time).
class RobotEnd {
 public:
  virtual ~RobotEnd() = default;
  /// What the program under test is given as its ~port.
  virtual std::string port() const = 0;
  /// Waits up to `timeout_ms` and reads what the program wrote (0 on timeout, and while no
  /// program is connected). \throws transport::TransportError as PseudoTerminal::read (a pty).
  virtual std::size_t read(uint8_t* buffer, std::size_t capacity, int timeout_ms) = 0;
  /// Writes one whole frame without blocking, the way a UART overruns: when the line cannot take
  /// the frame at once (or no program is connected yet), it is dropped and false is returned.
  virtual bool writeFrame(const std::vector<uint8_t>& frame) = 0;
};

/// A pseudo-terminal whose slave is linked at `link_path` (the program's port), or a listener on
/// 127.0.0.1 at an ephemeral port; the program's connection is accepted by read(), so some thread
/// must read.
std::unique_ptr<RobotEnd> openRobotEnd(Transport transport, const std::string& link_path);

}  // namespace serial_robot_driver::bench
