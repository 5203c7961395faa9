#include "serial_robot_driver/devices/body/sim/body_sim.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace serial_robot_driver::devices::body::sim {

using serial_robot_driver::sim::ChassisMotion;
using serial_robot_driver::sim::fromSeconds;
using serial_robot_driver::sim::Outbox;
using serial_robot_driver::sim::Outgoing;
using serial_robot_driver::sim::OutputKind;
using serial_robot_driver::sim::TimePoint;
using serial_robot_driver::sim::toSeconds;

// The SUM byte precedes the 1F 2F tail.
const OutputKind kTelemetryOutput{"telemetry", 3};

namespace {

int16_t clipToInt16(double value) {
  constexpr double kMin = std::numeric_limits<int16_t>::min();
  constexpr double kMax = std::numeric_limits<int16_t>::max();
  return static_cast<int16_t>(std::lround(std::clamp(value, kMin, kMax)));
}

// Yaw wrapped to [-pi, pi), as an attitude module reports it.
double wrapAngle(double radians) {
  double wrapped = std::fmod(radians + M_PI, 2.0 * M_PI);
  if (wrapped < 0) wrapped += 2.0 * M_PI;
  return wrapped - M_PI;
}

// Plausible standing readings for the 8 foot sensors (raw, no unit given by the vendor).
constexpr std::array<uint16_t, kFootSensorCount> kFootBaseline = {812, 790, 655, 701,
                                                                  820, 775, 640, 690};

}  // namespace

std::optional<std::array<double, 3>> parseGyroBias(const std::string& text) {
  std::array<double, 3> bias{};
  std::istringstream stream(text);
  for (std::size_t i = 0; i < 3; ++i) {
    std::string item;
    if (!std::getline(stream, item, ',') || item.empty()) return std::nullopt;
    std::size_t used = 0;
    try {
      bias[i] = std::stod(item, &used);
    } catch (const std::exception&) {
      return std::nullopt;
    }
    if (used != item.size() || !std::isfinite(bias[i])) return std::nullopt;
  }
  if (stream.peek() != std::char_traits<char>::eof()) return std::nullopt;  // a fourth value
  return bias;
}

BodySim::BodySim(const BodySimConfig& config, TimePoint now)
    : config_(config), last_step_(now), next_telemetry_(now), rng_(config.seed) {
  if (config_.servo_ids.size() > kMaxTelemetryServos) {
    config_.servo_ids.resize(kMaxTelemetryServos);
  }
  const uint16_t start = std::min(config_.initial_position, config_.max_position);
  for (uint8_t id : config_.servo_ids) {
    stats_.servos.push_back(BodySimServoState{id, static_cast<double>(start), start, 0});
  }
  if (config_.telemetry_rate_hz > 0) {
    telemetry_period_ = fromSeconds(1.0 / config_.telemetry_rate_hz);
    next_telemetry_ = now + telemetry_period_;
  }
}

void BodySim::handleSyncWrite(const uint8_t* data, std::size_t size) {
  const auto targets = decodeSyncWrite(data, size);
  if (!targets) {
    ++stats_.sync_writes_malformed;
    return;
  }
  ++stats_.sync_writes_ok;
  for (const ServoTarget& target : *targets) {
    auto servo = std::find_if(stats_.servos.begin(), stats_.servos.end(),
                              [&](const BodySimServoState& s) { return s.id == target.id; });
    if (servo == stats_.servos.end()) {
      ++stats_.sync_write_unknown_ids;
      continue;
    }
    servo->target = std::min(target.position, config_.max_position);
  }
}

void BodySim::advance(TimePoint now) {
  const double dt = toSeconds(now - last_step_);
  if (dt <= 0) return;
  last_step_ = now;
  const double max_step = config_.servo_speed * dt;
  for (BodySimServoState& servo : stats_.servos) {
    const double error = servo.target - servo.position;
    const double step = std::clamp(error, -max_step, max_step);
    servo.position += step;
    servo.speed = clipToInt16(step / dt);
  }
}

int16_t BodySim::noise() {
  if (!config_.imu_noise) return 0;
  return static_cast<int16_t>(std::uniform_int_distribution<int>(-2, 2)(rng_));
}

std::vector<uint8_t> BodySim::buildTelemetry(const ChassisMotion& chassis) {
  stats_.yaw_rad = wrapAngle(chassis.yaw_rad);
  Telemetry telemetry;
  telemetry.servo_count = stats_.servos.size();
  for (std::size_t i = 0; i < stats_.servos.size(); ++i) {
    telemetry.servos[i].position = static_cast<uint16_t>(std::lround(stats_.servos[i].position));
    telemetry.servos[i].speed = stats_.servos[i].speed;
  }
  constexpr double kRadToDeg = 180.0 / M_PI;
  telemetry.imu[kAccelX] = noise();
  telemetry.imu[kAccelY] = noise();
  telemetry.imu[kAccelZ] = clipToInt16(config_.accel_lsb_per_g + noise());
  const double lsb_per_rad_s = kRadToDeg * config_.gyro_lsb_per_dps;
  const auto& bias = config_.gyro_bias;
  telemetry.imu[kGyroX] = clipToInt16(bias[0] * lsb_per_rad_s + noise());
  telemetry.imu[kGyroY] = clipToInt16(bias[1] * lsb_per_rad_s + noise());
  telemetry.imu[kGyroZ] = clipToInt16((chassis.yaw_rate + bias[2]) * lsb_per_rad_s + noise());
  telemetry.imu[kRoll] = noise();
  telemetry.imu[kPitch] = noise();
  telemetry.imu[kYaw] = clipToInt16(stats_.yaw_rad * kRadToDeg * config_.angle_lsb_per_deg);

  switch (config_.foot_mode) {
    case FootMode::kNever:
      telemetry.has_foot = false;
      break;
    case FootMode::kAlways:
      telemetry.has_foot = true;
      break;
    case FootMode::kAlternate:
      telemetry.has_foot = stats_.telemetry_generated % 2 == 1;
      break;
  }
  if (telemetry.has_foot) {
    for (std::size_t j = 0; j < kFootSensorCount; ++j) {
      // A slow sway so consecutive readings differ a little.
      const double sway = 15.0 * std::sin(0.05 * static_cast<double>(stats_.telemetry_generated) +
                                          static_cast<double>(j));
      telemetry.foot[j] = static_cast<uint16_t>(kFootBaseline[j] + std::lround(sway));
    }
    ++stats_.telemetry_with_foot;
  }
  ++stats_.telemetry_generated;
  return encodeTelemetry(telemetry);
}

void BodySim::tick(TimePoint now, const ChassisMotion& chassis, Outbox* out) {
  if (config_.telemetry_rate_hz <= 0) {
    advance(now);
    return;
  }
  if (now - next_telemetry_ > std::chrono::seconds(1)) next_telemetry_ = now;  // after a stall
  while (next_telemetry_ <= now) {
    advance(next_telemetry_);
    out->push_back(Outgoing{&kTelemetryOutput, buildTelemetry(chassis)});
    next_telemetry_ += telemetry_period_;
  }
  advance(now);
}

TimePoint BodySim::nextEvent() const {
  if (config_.telemetry_rate_hz <= 0) return last_step_ + std::chrono::milliseconds(100);
  return next_telemetry_;
}

}  // namespace serial_robot_driver::devices::body::sim
