// RobotSim's --unplug-every fault: a port's pty closes (its link disappears) and comes back.
#pragma once

#include <functional>
#include <string>

#include "robot_sim_port.h"
#include "serial_robot_driver/sim/sim_options.h"
#include "serial_robot_driver/sim/sim_stats.h"

namespace serial_robot_driver::sim::detail {

/// Every --unplug-every seconds a port lets the host read what is already in flight (so "sent"
/// means "could be received"), closes its pty and, --unplug-duration later, opens a new one.
class PlugFaults {
 public:
  using EventSink = std::function<void(const std::string& text)>;
  /// `options` and `counters` must outlive it (RobotSim's own); `event` says what happened.
  PlugFaults(const SimOptions& options, SimStats& counters, EventSink event);

  /// When the port's first unplug comes (none without --unplug-every).
  void schedule(Port* port, TimePoint now);
  /// Starts, ends (unplugs) a drain or replugs, as due at `now`.
  void step(Port* port, TimePoint now);
  /// When step() has something to do next on the port (max: nothing).
  TimePoint nextEvent(const Port& port, TimePoint now) const;

 private:
  void beginDrain(Port* port, TimePoint now);
  /// Whether the host has read everything sent before the drain began.
  static bool drained(const Port& port);
  void unplug(Port* port, TimePoint now);
  void replug(Port* port, TimePoint now);

  const SimOptions& options_;
  SimStats& counters_;
  EventSink event_;
};

}  // namespace serial_robot_driver::sim::detail
