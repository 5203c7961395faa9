// A bus servo's health from its readings (voltage, current, power, temperature, status) against
// its own protection limits (over_volt_low, over_volt_high, over_temperature, over_power,
// over_current, read from the servo itself), and the overheat guard of ~servo_bus/protect.
// ROS-free, pure: device::ServoBus polls the values, the ROS layer reports the assessment.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace serial_robot_driver::devices::servo_bus {

/// The servo's protection limits, in the parameter table's units (mV, degC, mW, mA).
/// A limit of 0 is not set on the servo and is not checked.
struct ServoLimits {
  int64_t over_volt_low_mv = 0;   ///< the voltage must stay above it
  int64_t over_volt_high_mv = 0;  ///< the others: the value must stay below
  int64_t over_temperature_c = 0;
  int64_t over_power_mw = 0;
  int64_t over_current_ma = 0;
};

/// One health poll's values.
struct ServoReadings {
  int64_t voltage_mv = 0;
  int64_t current_ma = 0;
  int64_t power_mw = 0;
  int64_t temperature_c = 0;
  int64_t status = 0;  ///< servo_status, raw
};

enum class HealthLevel { kOk, kWarn, kError };
const char* toString(HealthLevel level);

struct HealthAssessment {
  HealthLevel level = HealthLevel::kOk;
  /// Empty when ok; else e.g. "servo 3: temperature 70 degC beyond over_temperature 65 degC",
  /// every limit concerned, the worst first.
  std::string message;
};

/// WARN within kWarnMargin of a limit (at 90 % of an upper limit or more, at 110 % of the lower
/// one or less), ERROR at or beyond it, naming the servo and the limit.
constexpr double kWarnMargin = 0.10;
HealthAssessment assessHealth(uint8_t id, const ServoReadings& readings, const ServoLimits& limits);

/// ~servo_bus/protect: trips when the temperature reaches the servo's over_temperature and
/// clears only once it has fallen kCoolDownC below it, so a servo near its limit does not toggle.
class OverheatGuard {
 public:
  static constexpr int64_t kCoolDownC = 5;
  /// The new state (true: protected) after a reading; a limit of 0 never trips.
  bool update(int64_t temperature_c, int64_t over_temperature_c);
  bool tripped() const { return tripped_; }

 private:
  bool tripped_ = false;
};

}  // namespace serial_robot_driver::devices::servo_bus
