// The body (servo controller board) in the simulator registry: robot_sim hosts BodySim through
// it, with its flags and its stats lines; its IMU reads the chassis motion from the world.
#include <cmath>
#include <memory>

#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::devices::body::sim {

namespace {

constexpr const char* kName = "body";

/// `body` with what its port's framer saw, and its stats-file lines.
serial_robot_driver::sim::DeviceSimStats statsOf(
    BodySimStats body, const serial_robot_driver::sim::PortCounters& ports) {
  body.port_checksum_errors = ports.own_port.checksum_errors;
  std::vector<serial_robot_driver::sim::StatsLine> lines{
      serial_robot_driver::sim::statsLine("telemetry_generated", body.telemetry_generated),
      serial_robot_driver::sim::statsLine("telemetry_with_foot", body.telemetry_with_foot),
      serial_robot_driver::sim::statsLine("sync_writes_ok", body.sync_writes_ok),
      serial_robot_driver::sim::statsLine("sync_writes_bad",
                                          body.sync_writes_malformed + body.port_checksum_errors),
      serial_robot_driver::sim::statsLine("sync_write_unknown_ids", body.sync_write_unknown_ids),
      serial_robot_driver::sim::statsLine("yaw_rad", body.yaw_rad),
  };
  for (const BodySimServoState& servo : body.servos) {
    const std::string prefix = "servo_" + std::to_string(servo.id);
    lines.push_back(
        serial_robot_driver::sim::statsLine(prefix + "_position", std::lround(servo.position)));
    lines.push_back(serial_robot_driver::sim::statsLine(prefix + "_target", servo.target));
    lines.push_back(serial_robot_driver::sim::statsLine(prefix + "_speed", servo.speed));
  }
  lines.push_back(serial_robot_driver::sim::statsLine("rx_frames_sync_write",
                                                      ports.all_ports.framesOf(kSyncWriteFrames)));
  return serial_robot_driver::sim::DeviceSimStats{kName, std::move(body), std::move(lines)};
}

serial_robot_driver::sim::DeviceSimStats leftOutStats(
    const serial_robot_driver::sim::PortCounters& ports) {
  return statsOf(BodySimStats{}, ports);
}

class BodySimDevice : public serial_robot_driver::sim::SimDevice {
 public:
  BodySimDevice(const BodySimConfig& config, serial_robot_driver::sim::TimePoint now)
      : body_(config, now) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   serial_robot_driver::sim::TimePoint /*at*/,
                   serial_robot_driver::sim::Outbox* /*out*/) override {
    if (family == kSyncWriteFrames) body_.handleSyncWrite(data, size);
  }
  void tick(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::SimWorld& world,
            serial_robot_driver::sim::Outbox* out) override {
    body_.tick(now, world.chassis, out);
  }
  serial_robot_driver::sim::TimePoint nextEvent() const override { return body_.nextEvent(); }

  serial_robot_driver::sim::DeviceSimStats stats(
      const serial_robot_driver::sim::PortCounters& ports) const override {
    return statsOf(body_.stats(), ports);
  }

 private:
  BodySim body_;
};

std::unique_ptr<serial_robot_driver::sim::SimDevice> makeBodySim(
    const serial_robot_driver::sim::HostedDeviceOptions& options, uint32_t seed,
    serial_robot_driver::sim::TimePoint now) {
  BodySimConfig config = options.configAs<BodySimConfig>();
  config.seed = seed;
  return std::make_unique<BodySimDevice>(config, now);
}

/// --gyro-bias X,Y,Z: rad/s on the sensor's axes.
serial_robot_driver::sim::SimDeviceOption gyroBiasOption() {
  serial_robot_driver::sim::SimDeviceOption option{
      "--gyro-bias", "X,Y,Z", "rad/s added to the gyro's sensor axes", nullptr, nullptr};
  option.apply = [](const std::string& value,
                    serial_robot_driver::sim::HostedDeviceOptions& device) {
    const auto bias = parseGyroBias(value);
    if (!bias)
      return serial_robot_driver::sim::badValue("--gyro-bias", value) + " (X,Y,Z in rad/s)";
    device.configAs<BodySimConfig>().gyro_bias = *bias;
    return std::string();
  };
  option.shown_default = [](const serial_robot_driver::sim::HostedDeviceOptions& defaults) {
    const auto& bias = defaults.configAs<BodySimConfig>().gyro_bias;
    return serial_robot_driver::sim::showDefault(bias[0]) + "," +
           serial_robot_driver::sim::showDefault(bias[1]) + "," +
           serial_robot_driver::sim::showDefault(bias[2]);
  };
  return option;
}

}  // namespace

BodySimConfig& bodyConfig(serial_robot_driver::sim::SimOptions& options) {
  return options.device(kName).configAs<BodySimConfig>();
}

const BodySimStats& bodyStats(const serial_robot_driver::sim::SimStats& stats) {
  return stats.countersOf<BodySimStats>(kName);
}

BodySimStats bodyStats(serial_robot_driver::sim::SimStats&& stats) {
  return stats.countersOf<BodySimStats>(kName);
}

}  // namespace serial_robot_driver::devices::body::sim

namespace serial_robot_driver::devices::body {

extern const serial_robot_driver::sim::SimDeviceModule kSimModule{
    .name = sim::kName,
    .description = "servo controller board",
    .hosted_by_default = true,
    .toggle_help = "leave the servo controller board out",
    .link_flag = "--body-link",
    .link_help = "own pty for the servo controller board",
    .seed_offset = 1,  // the IMU noise: seeded tests depend on --seed + 1
    .outputs = {&sim::kTelemetryOutput},
    .make = sim::makeBodySim,
    .left_out_stats = sim::leftOutStats,
    .options = {
        serial_robot_driver::sim::idListOption(
            "--servo-ids", "1,2", "body servo ids in telemetry order", kMaxTelemetryServos,
            "fit in a telemetry frame", &sim::BodySimConfig::servo_ids, true),
        serial_robot_driver::sim::numberOption(
            "--telemetry-rate", "HZ", "telemetry frames per second (0 = off)", 0.0, HUGE_VAL,
            &sim::BodySimConfig::telemetry_rate_hz, true),
        serial_robot_driver::sim::switchOption<sim::BodySimConfig>(
            "--foot", "every telemetry frame carries the foot block",
            [](sim::BodySimConfig& config) { config.foot_mode = sim::FootMode::kAlways; }),
        serial_robot_driver::sim::switchOption<sim::BodySimConfig>(
            "--foot-alternate", "every other telemetry frame carries it",
            [](sim::BodySimConfig& config) { config.foot_mode = sim::FootMode::kAlternate; }),
        serial_robot_driver::sim::numberOption("--servo-speed", "TICKS_S",
                                               "body servo speed bound in ticks/s", 0.0, HUGE_VAL,
                                               &sim::BodySimConfig::servo_speed, true),
        serial_robot_driver::sim::switchOption<sim::BodySimConfig>(
            "--imu-noise", "+-2 LSB noise on the IMU values",
            [](sim::BodySimConfig& config) { config.imu_noise = true; }),
        sim::gyroBiasOption(),
    }};

}  // namespace serial_robot_driver::devices::body
