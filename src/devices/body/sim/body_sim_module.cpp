// The body (servo controller board) in the simulator registry: robot_sim hosts BodySim through
// it, with its flags and its stats lines; its IMU reads the chassis motion from the world.
#include <cmath>
#include <memory>

#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::devices::body::sim {

using serial_robot_driver::sim::badValue;
using serial_robot_driver::sim::DeviceSimStats;
using serial_robot_driver::sim::HostedDeviceOptions;
using serial_robot_driver::sim::Outbox;
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

constexpr const char* kName = "body";

/// `body` with what its port's framer saw, and its stats-file lines.
DeviceSimStats statsOf(BodySimStats body, const PortCounters& ports) {
  body.port_checksum_errors = ports.own_port.checksum_errors;
  std::vector<StatsLine> lines{
      statsLine("telemetry_generated", body.telemetry_generated),
      statsLine("telemetry_with_foot", body.telemetry_with_foot),
      statsLine("sync_writes_ok", body.sync_writes_ok),
      statsLine("sync_writes_bad", body.sync_writes_malformed + body.port_checksum_errors),
      statsLine("sync_write_unknown_ids", body.sync_write_unknown_ids),
      statsLine("yaw_rad", body.yaw_rad),
  };
  for (const BodySimServoState& servo : body.servos) {
    const std::string prefix = "servo_" + std::to_string(servo.id);
    lines.push_back(statsLine(prefix + "_position", std::lround(servo.position)));
    lines.push_back(statsLine(prefix + "_target", servo.target));
    lines.push_back(statsLine(prefix + "_speed", servo.speed));
  }
  lines.push_back(statsLine("rx_frames_sync_write", ports.all_ports.framesOf(kSyncWriteFrames)));
  return DeviceSimStats{kName, std::move(body), std::move(lines)};
}

DeviceSimStats leftOutStats(const PortCounters& ports) { return statsOf(BodySimStats{}, ports); }

class BodySimDevice : public SimDevice {
 public:
  BodySimDevice(const BodySimConfig& config, TimePoint now) : body_(config, now) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   TimePoint /*at*/, Outbox* /*out*/) override {
    if (family == kSyncWriteFrames) body_.handleSyncWrite(data, size);
  }
  void tick(TimePoint now, SimWorld& world, Outbox* out) override {
    body_.tick(now, world.chassis, out);
  }
  TimePoint nextEvent() const override { return body_.nextEvent(); }

  DeviceSimStats stats(const PortCounters& ports) const override {
    return statsOf(body_.stats(), ports);
  }

 private:
  BodySim body_;
};

std::unique_ptr<SimDevice> makeBodySim(const HostedDeviceOptions& options, uint32_t seed,
                                       TimePoint now) {
  BodySimConfig config = options.configAs<BodySimConfig>();
  config.seed = seed;
  return std::make_unique<BodySimDevice>(config, now);
}

/// --gyro-bias X,Y,Z: rad/s on the sensor's axes.
SimDeviceOption gyroBiasOption() {
  SimDeviceOption option{"--gyro-bias", "X,Y,Z", "rad/s added to the gyro's sensor axes", nullptr,
                         nullptr};
  option.apply = [](const std::string& value, HostedDeviceOptions& device) {
    const auto bias = parseGyroBias(value);
    if (!bias) return badValue("--gyro-bias", value) + " (X,Y,Z in rad/s)";
    device.configAs<BodySimConfig>().gyro_bias = *bias;
    return std::string();
  };
  option.shown_default = [](const HostedDeviceOptions& defaults) {
    const auto& bias = defaults.configAs<BodySimConfig>().gyro_bias;
    return showDefault(bias[0]) + "," + showDefault(bias[1]) + "," + showDefault(bias[2]);
  };
  return option;
}

}  // namespace

BodySimConfig& bodyConfig(SimOptions& options) {
  return options.device(kName).configAs<BodySimConfig>();
}

const BodySimStats& bodyStats(const SimStats& stats) {
  return stats.countersOf<BodySimStats>(kName);
}

BodySimStats bodyStats(SimStats&& stats) { return stats.countersOf<BodySimStats>(kName); }

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
