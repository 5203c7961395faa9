// The servo bus in the simulator registry: robot_sim hosts ServoBusSim through it, with its flags,
// its stats lines and its share of the line faults (--servo-fault-rate on its answers).
#include <memory>

#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::devices::servo_bus::sim {

using serial_robot_driver::sim::badValue;
using serial_robot_driver::sim::DeviceSimStats;
using serial_robot_driver::sim::HostedDeviceOptions;
using serial_robot_driver::sim::Outbox;
using serial_robot_driver::sim::parseDouble;
using serial_robot_driver::sim::PortCounters;
using serial_robot_driver::sim::showDefault;
using serial_robot_driver::sim::SimDevice;
using serial_robot_driver::sim::SimDeviceOption;
using serial_robot_driver::sim::SimOptions;
using serial_robot_driver::sim::SimStats;
using serial_robot_driver::sim::SimWorld;
using serial_robot_driver::sim::StatsLine;
using serial_robot_driver::sim::statsLine;
using serial_robot_driver::sim::TimePoint;

namespace {

constexpr const char* kName = "servo_bus";

DeviceSimStats statsOf(ServoBusSimStats bus, const PortCounters& ports) {
  std::vector<StatsLine> lines{
      statsLine("servo_requests", bus.requests),
      statsLine("servo_answers", bus.answers),
      statsLine("servo_broadcasts", bus.broadcasts),
      statsLine("servo_unaddressed", bus.unaddressed),
      statsLine("servo_unknown_data_ids", bus.unknown_data_ids),
      statsLine("servo_malformed", bus.malformed),
      statsLine("servo_writes_rejected", bus.writes_rejected),
      statsLine("servo_stops_lost", bus.stops_lost),
  };
  for (const BusServoSnapshot& servo : bus.servos) {
    lines.push_back(
        statsLine("bus_servo_" + std::to_string(servo.id) + "_angle_deg", servo.angle_deg));
  }
  lines.push_back(statsLine("rx_frames_servo_request", ports.all_ports.framesOf(kRequestFrames)));
  return DeviceSimStats{kName, std::move(bus), std::move(lines)};
}

DeviceSimStats leftOutStats(const PortCounters& ports) {
  return statsOf(ServoBusSimStats{}, ports);
}

class ServoBusSimDevice : public SimDevice {
 public:
  ServoBusSimDevice(const ServoBusSimConfig& config, TimePoint now)
      : bus_(config, now), answer_fault_rate_(config.answer_fault_rate) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   TimePoint at, Outbox* /*out*/) override {
    // Answers leave from tick(), once their latency is over.
    if (family == kRequestFrames) bus_.handleRequest(data, size, at);
  }
  void tick(TimePoint now, SimWorld& /*world*/, Outbox* out) override {
    const std::size_t first = out->size();
    bus_.tick(now, out);
    for (std::size_t i = first; i < out->size(); ++i) {
      (*out)[i].garble_or_suppress_rate = answer_fault_rate_;
    }
  }
  TimePoint nextEvent() const override { return bus_.nextEvent(); }

  DeviceSimStats stats(const PortCounters& ports) const override {
    return statsOf(bus_.stats(), ports);
  }

 private:
  ServoBusSim bus_;
  double answer_fault_rate_;
};

std::unique_ptr<SimDevice> makeServoBusSim(const HostedDeviceOptions& options, uint32_t seed,
                                           TimePoint now) {
  ServoBusSimConfig config = options.configAs<ServoBusSimConfig>();
  config.seed = seed;
  return std::make_unique<ServoBusSimDevice>(config, now);
}

/// --servo-latency-ms: given in ms, kept in seconds.
SimDeviceOption latencyOption() {
  SimDeviceOption option{"--servo-latency-ms", "MS", "servo bus answer latency", nullptr, nullptr};
  option.apply = [](const std::string& value, HostedDeviceOptions& device) {
    double ms = 0;
    if (!parseDouble(value, &ms) || ms < 0) return badValue("--servo-latency-ms", value);
    device.configAs<ServoBusSimConfig>().answer_latency_s = ms / 1000.0;
    return std::string();
  };
  option.shown_default = [](const HostedDeviceOptions& defaults) {
    return showDefault(defaults.configAs<ServoBusSimConfig>().answer_latency_s * 1000.0);
  };
  return option;
}

}  // namespace

ServoBusSimConfig& servoBusConfig(SimOptions& options) {
  return options.device(kName).configAs<ServoBusSimConfig>();
}

const ServoBusSimStats& servoBusStats(const SimStats& stats) {
  return stats.countersOf<ServoBusSimStats>(kName);
}

ServoBusSimStats servoBusStats(SimStats&& stats) {
  return stats.countersOf<ServoBusSimStats>(kName);
}

}  // namespace serial_robot_driver::devices::servo_bus::sim

namespace serial_robot_driver::devices::servo_bus {

extern const serial_robot_driver::sim::SimDeviceModule kSimModule{
    .name = sim::kName,
    .description = "UART bus servos",
    .hosted_by_default = true,
    .toggle_help = "leave the servo bus out",
    .link_flag = "--servo-link",
    .link_help = "own pty for the servo bus",
    .seed_offset = 2,  // the drifting readings: seeded tests depend on --seed + 2
    .outputs = {&sim::kServoAnswerOutput},
    .make = sim::makeServoBusSim,
    .left_out_stats = sim::leftOutStats,
    .options = {
        serial_robot_driver::sim::idListOption("--bus-servo-ids", "0,1,2", "ids on the servo bus",
                                               SIZE_MAX, "", &sim::ServoBusSimConfig::servo_ids,
                                               true),
        serial_robot_driver::sim::idListOption("--offline-ids", "7", "ids that never answer",
                                               SIZE_MAX, "", &sim::ServoBusSimConfig::offline_ids,
                                               false),
        serial_robot_driver::sim::heldValueOption(
            "--servo-temperature", "ID:DEGC", "hold a bus servo's temperature at DEGC (repeatable)",
            &sim::ServoBusSimConfig::temperature_c),
        serial_robot_driver::sim::heldValueOption("--servo-voltage", "ID:MV",
                                                  "hold a bus servo's voltage at MV (repeatable)",
                                                  &sim::ServoBusSimConfig::voltage_mv),
        serial_robot_driver::sim::heldValueOption(
            "--servo-type", "ID:TYPE", "a bus servo's servo_type (repeatable; otherwise 257)",
            &sim::ServoBusSimConfig::servo_type),
        serial_robot_driver::sim::heldValueOption(
            "--servo-firmware", "ID:VERSION",
            "a bus servo's firmware_version (repeatable; otherwise 258)",
            &sim::ServoBusSimConfig::firmware_version),
        serial_robot_driver::sim::heldValueOption(
            "--servo-response-switch", "ID:0|1",
            "a bus servo's response_switch (repeatable; otherwise 0)",
            &sim::ServoBusSimConfig::response_switch),
        sim::latencyOption(),
        serial_robot_driver::sim::numberOption(
            "--servo-fault-rate", "P", "probability a servo answer is garbled or missing", 0.0, 1.0,
            &sim::ServoBusSimConfig::answer_fault_rate, false),
        serial_robot_driver::sim::wholeOption(
            "--lose-servo-stops", "N",
            "the next N SPIN stops to a bus servo are lost on the line: the servo "
            "keeps moving",
            1000000, &sim::ServoBusSimConfig::lost_stops, true),
    }};

}  // namespace serial_robot_driver::devices::servo_bus
