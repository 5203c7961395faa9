#include "serial_robot_driver/devices/servo_bus/servo_health.h"

#include <vector>

namespace serial_robot_driver::devices::servo_bus {

namespace {

struct Finding {
  HealthLevel level;
  std::string text;
};

std::string quantity(const char* name, int64_t value, const char* unit) {
  return std::string(name) + " " + std::to_string(value) + " " + unit;
}

/// `value` against an upper (or, with `lower`, a lower) limit; nothing when the limit is unset.
std::optional<Finding> check(const char* name, int64_t value, const char* limit_name, int64_t limit,
                             const char* unit, bool lower) {
  if (limit <= 0) return std::nullopt;
  const double margin = kWarnMargin * static_cast<double>(limit);
  HealthLevel level = HealthLevel::kOk;
  if (lower) {
    if (value <= limit) {
      level = HealthLevel::kError;
    } else if (static_cast<double>(value) <= static_cast<double>(limit) + margin) {
      level = HealthLevel::kWarn;
    }
  } else {
    if (value >= limit) {
      level = HealthLevel::kError;
    } else if (static_cast<double>(value) >= static_cast<double>(limit) - margin) {
      level = HealthLevel::kWarn;
    }
  }
  if (level == HealthLevel::kOk) return std::nullopt;
  const char* relation = level == HealthLevel::kError ? (lower ? " at or below " : " at or beyond ")
                                                      : " within 10 % of ";
  return Finding{level, quantity(name, value, unit) + relation + quantity(limit_name, limit, unit)};
}

}  // namespace

const char* toString(HealthLevel level) {
  switch (level) {
    case HealthLevel::kOk:
      return "ok";
    case HealthLevel::kWarn:
      return "warn";
    case HealthLevel::kError:
      return "error";
  }
  return "unknown";
}

HealthAssessment assessHealth(uint8_t id, const ServoReadings& r, const ServoLimits& l) {
  std::vector<Finding> findings;
  for (const std::optional<Finding>& finding : {
           check("temperature", r.temperature_c, "over_temperature", l.over_temperature_c, "degC",
                 false),
           check("voltage", r.voltage_mv, "over_volt_high", l.over_volt_high_mv, "mV", false),
           check("voltage", r.voltage_mv, "over_volt_low", l.over_volt_low_mv, "mV", true),
           check("current", r.current_ma, "over_current", l.over_current_ma, "mA", false),
           check("power", r.power_mw, "over_power", l.over_power_mw, "mW", false),
       }) {
    if (finding) findings.push_back(*finding);
  }
  HealthAssessment assessment;
  // The errors first, then the warnings.
  for (HealthLevel level : {HealthLevel::kError, HealthLevel::kWarn}) {
    for (const Finding& finding : findings) {
      if (finding.level != level) continue;
      if (assessment.level == HealthLevel::kOk) assessment.level = level;
      assessment.message +=
          (assessment.message.empty() ? "servo " + std::to_string(id) + ": " : "; ") + finding.text;
    }
  }
  return assessment;
}

bool OverheatGuard::update(int64_t temperature_c, int64_t over_temperature_c) {
  if (over_temperature_c <= 0) {
    tripped_ = false;
  } else if (!tripped_) {
    tripped_ = temperature_c >= over_temperature_c;
  } else {
    tripped_ = temperature_c > over_temperature_c - kCoolDownC;
  }
  return tripped_;
}

}  // namespace serial_robot_driver::devices::servo_bus
