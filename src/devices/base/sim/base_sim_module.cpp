// The base in the simulator registry: robot_sim hosts BaseSim through it, with its flags, its
// stats lines and the chassis motion it writes into the world the other devices read.
#include <memory>

#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::devices::base::sim {

using serial_robot_driver::sim::ChassisMotion;
using serial_robot_driver::sim::DeviceSimStats;
using serial_robot_driver::sim::HostedDeviceOptions;
using serial_robot_driver::sim::Outbox;
using serial_robot_driver::sim::PortCounters;
using serial_robot_driver::sim::SimDevice;
using serial_robot_driver::sim::SimOptions;
using serial_robot_driver::sim::SimStats;
using serial_robot_driver::sim::SimWorld;
using serial_robot_driver::sim::statsLine;
using serial_robot_driver::sim::TimePoint;

namespace {

constexpr const char* kName = "base";

DeviceSimStats statsOf(const BaseSimStats& base, const PortCounters& ports) {
  return DeviceSimStats{kName,
                        base,
                        {
                            statsLine("base_frames_received", base.frames_received),
                            statsLine("base_seq_gaps", base.seq_gaps),
                            statsLine("base_resets", base.resets),
                            statsLine("base_speed_frames_applied", base.speed_frames_applied),
                            statsLine("base_speed_frames_ignored", base.speed_frames_ignored),
                            statsLine("base_errors_sent", base.errors_sent),
                            statsLine("base_timeouts", base.timeouts),
                            statsLine("base_battery_requests", base.battery_requests),
                            statsLine("base_encoder_clears", base.encoder_clears),
                            statsLine("base_unknown_frames", base.unknown_frames),
                            statsLine("base_in_error", base.in_error ? 1 : 0),
                            statsLine("left_ticks", base.left_ticks),
                            statsLine("right_ticks", base.right_ticks),
                            statsLine("base_x_m", base.x_m),
                            statsLine("base_y_m", base.y_m),
                            statsLine("base_yaw_rad", base.yaw_rad),
                            statsLine("last_left_speed", base.last_left_speed),
                            statsLine("last_right_speed", base.last_right_speed),
                            statsLine("rx_frames_base", ports.all_ports.framesOf(kFrames)),
                        }};
}

DeviceSimStats leftOutStats(const PortCounters& ports) { return statsOf(BaseSimStats{}, ports); }

class BaseSimDevice : public SimDevice {
 public:
  BaseSimDevice(const BaseSimConfig& config, TimePoint now) : base_(config, now) {}

  void handleFrame(const protocol::FrameFamily& family, const uint8_t* data, std::size_t size,
                   TimePoint at, Outbox* out) override {
    if (family == kFrames) base_.handleFrame(data, size, at, out);
  }
  void tick(TimePoint now, SimWorld& world, Outbox* out) override {
    base_.tick(now, out);
    // Whatever rides on the base (the board's IMU) sees its true heading, slip included.
    world.chassis = ChassisMotion{base_.stats().yaw_rad, base_.yawRate()};
  }
  TimePoint nextEvent() const override { return base_.nextEvent(); }

  DeviceSimStats stats(const PortCounters& ports) const override {
    return statsOf(base_.stats(), ports);
  }

 private:
  BaseSim base_;
};

std::unique_ptr<SimDevice> makeBaseSim(const HostedDeviceOptions& options, uint32_t /*seed*/,
                                       TimePoint now) {
  return std::make_unique<BaseSimDevice>(options.configAs<BaseSimConfig>(), now);
}

}  // namespace

BaseSimConfig& baseConfig(SimOptions& options) {
  return options.device(kName).configAs<BaseSimConfig>();
}

const BaseSimStats& baseStats(const SimStats& stats) {
  return stats.countersOf<BaseSimStats>(kName);
}

BaseSimStats baseStats(SimStats&& stats) { return stats.countersOf<BaseSimStats>(kName); }

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
