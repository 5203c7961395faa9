#include "serial_robot_driver/sim/sim_stats.h"

#include <iomanip>
#include <sstream>

namespace serial_robot_driver::sim {

const SendCounters& SimStats::sentOf(const OutputKind& kind) const& {
  static const SendCounters kNeverSent{};
  for (const auto& [sent_kind, counters] : sent) {
    if (sent_kind == &kind) return counters;
  }
  return kNeverSent;
}

const DeviceSimStats* SimStats::findDevice(const std::string& name) const {
  for (const DeviceSimStats& device : devices) {
    if (device.name == name) return &device;
  }
  return nullptr;
}

std::string formatStats(const SimStats& stats) {
  std::ostringstream out;
  const auto line = [&out](const std::string& key, auto value) {
    out << key << ' ' << value << '\n';
  };
  out << std::fixed << std::setprecision(3);
  line("uptime_s", stats.uptime_s);
  // The devices format their own values (their precision included).
  for (const DeviceSimStats& device : stats.devices) {
    for (const auto& [key, value] : device.lines) line(key, value);
  }
  for (const auto& [kind, counters] : stats.sent) {
    const std::string name = kind->name;
    line(name + "_sent_intact", counters.intact);
    line(name + "_sent_damaged", counters.damaged);
    line(name + "_suppressed", counters.suppressed);
    line(name + "_discarded", counters.discarded);
  }

  line("rx_bytes", stats.bytes_received);
  line("rx_bytes_skipped", stats.framer.bytes_skipped);
  line("rx_checksum_errors", stats.framer.checksum_errors);
  line("rx_bad_lengths", stats.framer.bad_lengths);
  line("rx_unknown_commands", stats.framer.unknown_commands);
  line("frames_for_absent_device", stats.frames_for_absent_device);
  line("tx_bytes", stats.bytes_sent);
  line("garbage_bursts", stats.garbage_bursts);
  line("garbage_bytes", stats.garbage_bytes);
  line("unplugs", stats.unplugs);
  line("replugs", stats.replugs);
  return out.str();
}

}  // namespace serial_robot_driver::sim
