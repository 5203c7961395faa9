// Simulated servo controller board (docs/protocols.md, section 2).
//
// Streams telemetry frames at a fixed rate: every configured servo moves toward its last
// sync-write target at a bounded speed and reports that speed; the IMU sees gravity on z and the
// wheeled base's true heading and yaw rate (the board sits on the base); the optional foot block
// carries plausible pressure readings.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/sim/sim_options.h"
#include "serial_robot_driver/sim/sim_stats.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::devices::body::sim {

/// When telemetry frames carry the 16-byte foot block.
enum class FootMode { kNever, kAlways, kAlternate };

struct BodySimConfig {
  std::vector<uint8_t> servo_ids = {1, 2};
  double telemetry_rate_hz = 50.0;  ///< 0: no telemetry at all
  FootMode foot_mode = FootMode::kNever;
  double servo_speed = 2048.0;  ///< ticks/s, the bound on every servo's motion
  uint16_t initial_position = 2048;
  uint16_t max_position = 4095;  ///< targets are clamped to 0..max_position
  bool imu_noise = false;        ///< add +-2 LSB of noise to the IMU values
  /// rad/s added to the gyro on each sensor axis (x, y, z): a bias for imu/calibrate to find.
  std::array<double, 3> gyro_bias{0.0, 0.0, 0.0};
  // IMU raw scales of docs/protocols.md (16 g, 2000 deg/s, 180 deg full scale over 32768).
  double accel_lsb_per_g = 32768.0 / 16.0;
  double gyro_lsb_per_dps = 32768.0 / 2000.0;
  double angle_lsb_per_deg = 32768.0 / 180.0;
  uint32_t seed = 1;
};

/// "X,Y,Z" (three finite numbers) as robot_sim's --gyro-bias reads it; nullopt when malformed.
std::optional<std::array<double, 3>> parseGyroBias(const std::string& text);

struct BodySimServoState {
  uint8_t id = 0;
  double position = 0.0;  ///< ticks
  uint16_t target = 0;
  int16_t speed = 0;  ///< ticks/s of the last step, as reported
};

struct BodySimStats {
  uint64_t telemetry_generated = 0;
  uint64_t telemetry_with_foot = 0;
  uint64_t sync_writes_ok = 0;
  uint64_t sync_writes_malformed = 0;   ///< verified CRC but a layout decodeSyncWrite rejected
  uint64_t sync_write_unknown_ids = 0;  ///< targets for ids the board does not have
  double yaw_rad = 0.0;                 ///< the heading the IMU reports (the chassis')
  std::vector<BodySimServoState> servos;
  /// CRC failures the framer of the board's port saw: bad sync-writes (on a shared port the
  /// framer cannot tell whose a broken frame was, so bad frames of the other devices count too).
  /// Filled by robot_sim.
  uint64_t port_checksum_errors = 0;
};

/// Telemetry frames: their SUM byte precedes the 1F 2F tail.
extern const serial_robot_driver::sim::OutputKind kTelemetryOutput;

class BodySim {
 public:
  BodySim(const BodySimConfig& config, serial_robot_driver::sim::TimePoint now);

  /// A CRC-verified FF FF FD 00 frame from the host.
  void handleSyncWrite(const uint8_t* data, std::size_t size);
  /// Moves the servos up to `now`; emits the telemetry frames that are due, their IMU reporting
  /// `chassis` (the true heading and yaw rate now of what the board is mounted on).
  void tick(serial_robot_driver::sim::TimePoint now,
            const serial_robot_driver::sim::ChassisMotion& chassis,
            serial_robot_driver::sim::Outbox* out);
  serial_robot_driver::sim::TimePoint nextEvent() const;

  const BodySimStats& stats() const { return stats_; }

 private:
  void advance(serial_robot_driver::sim::TimePoint now);
  std::vector<uint8_t> buildTelemetry(const serial_robot_driver::sim::ChassisMotion& chassis);
  int16_t noise();

  BodySimConfig config_;
  BodySimStats stats_;
  serial_robot_driver::sim::TimePoint last_step_;
  serial_robot_driver::sim::TimePoint next_telemetry_;
  serial_robot_driver::sim::Clock::duration telemetry_period_{};
  std::mt19937 rng_;
};

/// The board's settings in robot_sim's options (made with their defaults on first use).
BodySimConfig& bodyConfig(serial_robot_driver::sim::SimOptions& options);
/// The board's counters in a stats snapshot (all zero when it was not simulated).
const BodySimStats& bodyStats(const serial_robot_driver::sim::SimStats& stats);
/// The same of a temporary snapshot (bodyStats(robot.stats())): a copy, which outlives it.
BodySimStats bodyStats(serial_robot_driver::sim::SimStats&& stats);

}  // namespace serial_robot_driver::devices::body::sim
