// What a device's diagnostic status says (level, summary, key/value pairs), decided in the
// ROS-free core so that it can be unit-tested without a master. The ROS layer only copies it into
// a diagnostic_updater::DiagnosticStatusWrapper (ros_layer::writeStatusReport), so the rules here
// mirror that wrapper's: mergeSummary() joins problems with "; ", a bool reads "True"/"False" and
// a number is streamed (std::ostringstream, default precision).
#pragma once

#include <cstdint>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace serial_robot_driver::core {

/// The values of diagnostic_msgs/DiagnosticStatus's levels.
enum class StatusLevel : uint8_t { kOk = 0, kWarn = 1, kError = 2, kStale = 3 };
const char* toString(StatusLevel level);

/// A serial port as a status names it.
struct PortState {
  std::string path;
  bool connected = false;
};

struct StatusReport {
  StatusLevel level = StatusLevel::kOk;
  std::string message;
  std::string hardware_id;                                  ///< empty: the updater's own
  std::vector<std::pair<std::string, std::string>> values;  ///< in the order they were added

  void summary(StatusLevel new_level, std::string new_message);
  /// As DiagnosticStatusWrapper::mergeSummary: two problems (levels above OK) are both named,
  /// joined by "; "; otherwise the worse level and its message win.
  void mergeSummary(StatusLevel other_level, const std::string& other_message);
  void mergeSummaryf(StatusLevel other_level, const char* format, ...)
      __attribute__((format(printf, 3, 4)));

  void add(std::string key, std::string value);
  void add(std::string key, const char* value) { add(std::move(key), std::string(value)); }
  void add(std::string key, bool value) {
    add(std::move(key), std::string(value ? "True" : "False"));
  }
  template <typename Number, typename = std::enable_if_t<std::is_arithmetic_v<Number>>>
  void add(std::string key, Number value) {
    if constexpr (std::is_integral_v<Number> && sizeof(Number) > 1) {
      // The same digits as a stream's, without building one (most values are counters).
      add(std::move(key), std::to_string(value));
    } else {
      std::ostringstream text;  // chars as characters, floating point as %g: a stream's text
      text << value;
      add(std::move(key), text.str());
    }
  }
  void addf(std::string key, const char* format, ...) __attribute__((format(printf, 3, 4)));

  /// The first value added under `key`, or null.
  const std::string* find(const std::string& key) const;
};

}  // namespace serial_robot_driver::core
