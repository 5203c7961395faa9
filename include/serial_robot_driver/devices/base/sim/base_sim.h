// Simulated AP1 wheeled base (docs/protocols.md, section 1).
//
// Integrates wheel-speed frames into encoder counters at the PID rate, answers battery requests and
// enforces the vendor heartbeat: more than `heartbeat_timeout_s` without a host frame puts the base
// into the error state, in which it stops the wheels, reports error status FF once per
// `error_repeat_s` and ignores speed frames until a Reset arrives.
#pragma once

#include <cstddef>
#include <cstdint>

#include "serial_robot_driver/devices/base/base_codec.h"
#include "serial_robot_driver/sim/sim_options.h"
#include "serial_robot_driver/sim/sim_stats.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::devices::base::sim {

struct BaseSimConfig {
  uint8_t battery_percent = 87;  ///< reported in battery replies (0..100)
  double pid_rate_hz = 50.0;     ///< counters advance once per PID period
  double heartbeat_timeout_s = 1.0;
  double error_repeat_s = 1.0;         ///< FF error frame repeat period while in error
  int16_t max_ticks_per_period = 200;  ///< the base clamps faster commands
  // Geometry, only used to turn wheel ticks into the body's yaw rate (docs/node_api.md defaults).
  double wheel_diameter_m = 0.25;
  double encoder_resolution = 1600.0;
  double wheel_separation_m = 0.40;
  /// Wheel slip while turning: the chassis turns by (1 - turn_slip) of the turn its wheel ticks
  /// command (0..1). The encoders still count every tick: odometry from the ticks overestimates
  /// the turn, as it does on a slippery floor.
  double turn_slip = 0.0;
};

struct BaseSimStats {
  uint64_t frames_received = 0;
  uint64_t seq_gaps = 0;  ///< frames whose SEQ was not the previous SEQ + 1
  uint64_t resets = 0;
  uint64_t speed_frames_applied = 0;
  uint64_t speed_frames_ignored = 0;  ///< received while in the error state
  uint64_t errors_sent = 0;           ///< FF error status frames emitted
  uint64_t timeouts = 0;              ///< times the heartbeat expired
  uint64_t battery_requests = 0;
  uint64_t encoder_clears = 0;
  uint64_t unknown_frames = 0;  ///< unknown MSGID or malformed content
  int64_t left_ticks = 0;
  int64_t right_ticks = 0;
  /// The chassis pose from the speeds applied, one midpoint step per PID period (m, m, rad): the
  /// reference the driver's odometry is checked against. Slip included: the true pose.
  double x_m = 0;
  double y_m = 0;
  double yaw_rad = 0;
  int16_t last_left_speed = 0;  ///< ticks per PID period in force (0 after a timeout)
  int16_t last_right_speed = 0;
  bool in_error = false;
};

/// The base's replies (battery, error status): checksum in the last byte.
extern const serial_robot_driver::sim::OutputKind kBaseReplyOutput;

class BaseSim {
 public:
  BaseSim(const BaseSimConfig& config, serial_robot_driver::sim::TimePoint now);

  /// A verified 55 AA frame from the host (the framer has checked LEN and XOR).
  void handleFrame(const uint8_t* data, std::size_t size, serial_robot_driver::sim::TimePoint now,
                   serial_robot_driver::sim::Outbox* out);
  /// Runs the PID periods and the heartbeat up to `now`.
  void tick(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::Outbox* out);
  /// When tick() next has something to do.
  serial_robot_driver::sim::TimePoint nextEvent() const;

  const BaseSimStats& stats() const { return stats_; }
  /// True yaw rate of the chassis (rad/s, counter-clockwise positive) from the speeds in force,
  /// slip included.
  double yawRate() const;
  void setBatteryPercent(uint8_t percent) { config_.battery_percent = percent; }

 private:
  void emit(serial_robot_driver::sim::Outbox* out, std::vector<uint8_t> frame);
  void enterError(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::Outbox* out);
  void advancePose();

  BaseSimConfig config_;
  BaseSimStats stats_;
  serial_robot_driver::sim::Clock::duration pid_period_;
  serial_robot_driver::sim::TimePoint next_pid_;
  serial_robot_driver::sim::TimePoint last_host_frame_;
  serial_robot_driver::sim::TimePoint next_error_frame_;
  bool have_seq_ = false;
  uint8_t expected_seq_ = 0;
  SequenceCounter reply_seq_;
};

/// The base's settings in robot_sim's options (made with their defaults on first use).
BaseSimConfig& baseConfig(serial_robot_driver::sim::SimOptions& options);
/// The base's counters in a stats snapshot (all zero when it was not simulated).
const BaseSimStats& baseStats(const serial_robot_driver::sim::SimStats& stats);
/// The same of a temporary snapshot (baseStats(robot.stats())): a copy, which outlives it.
BaseSimStats baseStats(serial_robot_driver::sim::SimStats&& stats);

}  // namespace serial_robot_driver::devices::base::sim
