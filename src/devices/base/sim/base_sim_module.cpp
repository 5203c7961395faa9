// The base in the simulator registry: robot_sim hosts BaseSim through it, with its flags, its
// stats lines and the chassis motion it writes into the world the other devices read.
#include <memory>

#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::devices::base::sim {

namespace {

constexpr const char* kName = "base";

serial_robot_driver::sim::DeviceSimStats statsOf(
    const BaseSimStats& base, const serial_robot_driver::sim::PortCounters& ports) {
  return serial_robot_driver::sim::DeviceSimStats{
      kName,
      base,
      {
          serial_robot_driver::sim::statsLine("base_frames_received", base.frames_received),
          serial_robot_driver::sim::statsLine("base_seq_gaps", base.seq_gaps),
          serial_robot_driver::sim::statsLine("base_resets", base.resets),
          serial_robot_driver::sim::statsLine("base_speed_frames_applied",
                                              base.speed_frames_applied),
          serial_robot_driver::sim::statsLine("base_speed_frames_ignored",
                                              base.speed_frames_ignored),
          serial_robot_driver::sim::statsLine("base_errors_sent", base.errors_sent),
          serial_robot_driver::sim::statsLine("base_timeouts", base.timeouts),
          serial_robot_driver::sim::statsLine("base_battery_requests", base.battery_requests),
          serial_robot_driver::sim::statsLine("base_encoder_clears", base.encoder_clears),
          serial_robot_driver::sim::statsLine("base_unknown_frames", base.unknown_frames),
          serial_robot_driver::sim::statsLine("base_in_error", base.in_error ? 1 : 0),
          serial_robot_driver::sim::statsLine("left_ticks", base.left_ticks),
          serial_robot_driver::sim::statsLine("right_ticks", base.right_ticks),
          serial_robot_driver::sim::statsLine("base_x_m", base.x_m),
          serial_robot_driver::sim::statsLine("base_y_m", base.y_m),
          serial_robot_driver::sim::statsLine("base_yaw_rad", base.yaw_rad),
          serial_robot_driver::sim::statsLine("last_left_speed", base.last_left_speed),
          serial_robot_driver::sim::statsLine("last_right_speed", base.last_right_speed),
          serial_robot_driver::sim::statsLine("rx_frames_base", ports.all_ports.framesOf(kFrames)),
      }};
}

serial_robot_driver::sim::DeviceSimStats leftOutStats(
    const serial_robot_driver::sim::PortCounters& ports) {
  return statsOf(BaseSimStats{}, ports);
}

class BaseSimDevice : public serial_robot_driver::sim::SimDevice {
 public:
  BaseSimDevice(const BaseSimConfig& config, serial_robot_driver::sim::TimePoint now)
      : base_(config, now) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   serial_robot_driver::sim::TimePoint at,
                   serial_robot_driver::sim::Outbox* out) override {
    if (family == kFrames) base_.handleFrame(data, size, at, out);
  }
  void tick(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::SimWorld& world,
            serial_robot_driver::sim::Outbox* out) override {
    base_.tick(now, out);
    // Whatever rides on the base (the board's IMU) sees its true heading, slip included.
    world.chassis = serial_robot_driver::sim::ChassisMotion{base_.stats().yaw_rad, base_.yawRate()};
  }
  serial_robot_driver::sim::TimePoint nextEvent() const override { return base_.nextEvent(); }

  serial_robot_driver::sim::DeviceSimStats stats(
      const serial_robot_driver::sim::PortCounters& ports) const override {
    return statsOf(base_.stats(), ports);
  }

 private:
  BaseSim base_;
};

std::unique_ptr<serial_robot_driver::sim::SimDevice> makeBaseSim(
    const serial_robot_driver::sim::HostedDeviceOptions& options, uint32_t /*seed*/,
    serial_robot_driver::sim::TimePoint now) {
  return std::make_unique<BaseSimDevice>(options.configAs<BaseSimConfig>(), now);
}

}  // namespace

BaseSimConfig& baseConfig(serial_robot_driver::sim::SimOptions& options) {
  return options.device(kName).configAs<BaseSimConfig>();
}

const BaseSimStats& baseStats(const serial_robot_driver::sim::SimStats& stats) {
  return stats.countersOf<BaseSimStats>(kName);
}

BaseSimStats baseStats(serial_robot_driver::sim::SimStats&& stats) {
  return stats.countersOf<BaseSimStats>(kName);
}

}  // namespace serial_robot_driver::devices::base::sim

namespace serial_robot_driver::devices::base {

extern const serial_robot_driver::sim::SimDeviceModule kSimModule{
    .name = sim::kName,
    .description = "AP1 base",
    .hosted_by_default = true,
    .toggle_help = "leave the base out",
    .link_flag = "--base-link",
    .link_help = "own pty for the base (devices naming the same link share a pty)",
    .seed_offset = 0,  // the base draws nothing at random
    .outputs = {&sim::kBaseReplyOutput},
    .make = sim::makeBaseSim,
    .left_out_stats = sim::leftOutStats,
    .options = {
        serial_robot_driver::sim::wholeOption("--battery", "PCT",
                                              "battery percent the base reports", 100,
                                              &sim::BaseSimConfig::battery_percent, true),
        serial_robot_driver::sim::numberOption(
            "--turn-slip", "FRACTION",
            "wheel slip: the base turns by (1 - FRACTION) of the commanded yaw rate "
            "(0..1); the IMU reports the true turn",
            0.0, 1.0, &sim::BaseSimConfig::turn_slip, false),
    }};

}  // namespace serial_robot_driver::devices::base
