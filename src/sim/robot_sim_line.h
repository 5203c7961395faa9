// RobotSim's serial lines: what goes through each port's line both ways, with the line's own
// faults, paced at --pace-baud when it is set.
#pragma once

#include <cstddef>
#include <cstdint>

#include "robot_sim_port.h"
#include "serial_robot_driver/sim/sim_options.h"
#include "serial_robot_driver/sim/sim_stats.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::sim::detail {

/// The devices' frames into a port's pty (garbled or suppressed by their own rate, checksum
/// corrupted or a byte dropped by --corrupt-rate / --drop-rate, --garbage-rate bursts between
/// them), the host's bytes out of it to the framer; both no faster than --pace-baud allows.
class Line {
 public:
  /// Both must outlive the line (RobotSim's own).
  Line(const SimOptions& options, SimStats& counters);

  /// Queues a frame for the port (its faults applied, or discarded when the port is unplugged or
  /// its backlog full) and writes what the line carries by now.
  void send(Port* port, Outgoing frame);
  /// Writes what the pty takes (and, paced, what is through the line by now), never blocking.
  void flush(Port* port);
  /// --garbage-rate: when the first burst comes.
  void scheduleGarbage(Port* port, TimePoint now);
  /// --garbage-rate: a burst into the backlog when one is due, and when the next one comes.
  void injectGarbage(Port* port, TimePoint now);
  /// What the host wrote, read at `read_at`: to the framer, or (paced) in flight until its last
  /// bit is through the line.
  void receive(Port* port, const uint8_t* data, std::size_t size, TimePoint read_at);
  /// --pace-baud: hands the framer what the host wrote once its last bit is through the line.
  void deliverArrived(Port* port, TimePoint now);
  /// When the line has something to do next on the port (max: nothing).
  TimePoint nextEvent(const Port& port) const;
  /// --pace-baud: when flush() has the next bytes of the backlog through the line (max: none).
  TimePoint nextSendAt(const Port* port) const;

 private:
  /// How long the line takes to carry `bytes` at pace_baud (10 bits a byte).
  Clock::duration lineTime(std::size_t bytes) const;

  const SimOptions& options_;
  SimStats& counters_;
};

}  // namespace serial_robot_driver::sim::detail
