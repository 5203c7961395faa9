// The servo bus in the simulator registry: robot_sim hosts ServoBusSim through it, with its flags,
// its stats lines and its share of the line faults (--servo-fault-rate on its answers).
#include <memory>

#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::devices::servo_bus::sim {

namespace {

constexpr const char* kName = "servo_bus";

serial_robot_driver::sim::DeviceSimStats statsOf(
    ServoBusSimStats bus, const serial_robot_driver::sim::PortCounters& ports) {
  std::vector<serial_robot_driver::sim::StatsLine> lines{
      serial_robot_driver::sim::statsLine("servo_requests", bus.requests),
      serial_robot_driver::sim::statsLine("servo_answers", bus.answers),
      serial_robot_driver::sim::statsLine("servo_broadcasts", bus.broadcasts),
      serial_robot_driver::sim::statsLine("servo_unaddressed", bus.unaddressed),
      serial_robot_driver::sim::statsLine("servo_unknown_data_ids", bus.unknown_data_ids),
      serial_robot_driver::sim::statsLine("servo_malformed", bus.malformed),
      serial_robot_driver::sim::statsLine("servo_writes_rejected", bus.writes_rejected),
      serial_robot_driver::sim::statsLine("servo_stops_lost", bus.stops_lost),
  };
  for (const BusServoSnapshot& servo : bus.servos) {
    lines.push_back(serial_robot_driver::sim::statsLine(
        "bus_servo_" + std::to_string(servo.id) + "_angle_deg", servo.angle_deg));
  }
  lines.push_back(serial_robot_driver::sim::statsLine("rx_frames_servo_request",
                                                      ports.all_ports.framesOf(kRequestFrames)));
  return serial_robot_driver::sim::DeviceSimStats{kName, std::move(bus), std::move(lines)};
}

serial_robot_driver::sim::DeviceSimStats leftOutStats(
    const serial_robot_driver::sim::PortCounters& ports) {
  return statsOf(ServoBusSimStats{}, ports);
}

class ServoBusSimDevice : public serial_robot_driver::sim::SimDevice {
 public:
  ServoBusSimDevice(const ServoBusSimConfig& config, serial_robot_driver::sim::TimePoint now)
      : bus_(config, now), answer_fault_rate_(config.answer_fault_rate) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   serial_robot_driver::sim::TimePoint at,
                   serial_robot_driver::sim::Outbox* /*out*/) override {
    // Answers leave from tick(), once their latency is over.
    if (family == kRequestFrames) bus_.handleRequest(data, size, at);
  }
  void tick(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::SimWorld& /*world*/,
            serial_robot_driver::sim::Outbox* out) override {
    const std::size_t first = out->size();
    bus_.tick(now, out);
    for (std::size_t i = first; i < out->size(); ++i) {
      (*out)[i].garble_or_suppress_rate = answer_fault_rate_;
    }
  }
  serial_robot_driver::sim::TimePoint nextEvent() const override { return bus_.nextEvent(); }

  serial_robot_driver::sim::DeviceSimStats stats(
      const serial_robot_driver::sim::PortCounters& ports) const override {
    return statsOf(bus_.stats(), ports);
  }

 private:
  ServoBusSim bus_;
  double answer_fault_rate_;
};

std::unique_ptr<serial_robot_driver::sim::SimDevice> makeServoBusSim(
    const serial_robot_driver::sim::HostedDeviceOptions& options, uint32_t seed,
    serial_robot_driver::sim::TimePoint now) {
  ServoBusSimConfig config = options.configAs<ServoBusSimConfig>();
  config.seed = seed;
  return std::make_unique<ServoBusSimDevice>(config, now);
}

/// --servo-latency-ms: given in ms, kept in seconds.
serial_robot_driver::sim::SimDeviceOption latencyOption() {
  serial_robot_driver::sim::SimDeviceOption option{"--servo-latency-ms", "MS",
                                                   "servo bus answer latency", nullptr, nullptr};
  option.apply = [](const std::string& value,
                    serial_robot_driver::sim::HostedDeviceOptions& device) {
    double ms = 0;
    if (!serial_robot_driver::sim::parseDouble(value, &ms) || ms < 0)
      return serial_robot_driver::sim::badValue("--servo-latency-ms", value);
    device.configAs<ServoBusSimConfig>().answer_latency_s = ms / 1000.0;
    return std::string();
  };
  option.shown_default = [](const serial_robot_driver::sim::HostedDeviceOptions& defaults) {
    return serial_robot_driver::sim::showDefault(
        defaults.configAs<ServoBusSimConfig>().answer_latency_s * 1000.0);
  };
  return option;
}

}  // namespace

ServoBusSimConfig& servoBusConfig(serial_robot_driver::sim::SimOptions& options) {
  return options.device(kName).configAs<ServoBusSimConfig>();
}

const ServoBusSimStats& servoBusStats(const serial_robot_driver::sim::SimStats& stats) {
  return stats.countersOf<ServoBusSimStats>(kName);
}

ServoBusSimStats servoBusStats(serial_robot_driver::sim::SimStats&& stats) {
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
