#include "serial_robot_driver/core/status_report.h"

#include <cstdarg>
#include <cstdio>

namespace serial_robot_driver::core {

namespace {
// DiagnosticStatusWrapper formats into 1000 bytes as well; longer text is cut the same way.
std::string vformat(const char* format, va_list args) {
  char text[1000];
  std::vsnprintf(text, sizeof(text), format, args);
  return text;
}
}  // namespace

const char* toString(StatusLevel level) {
  switch (level) {
    case StatusLevel::kOk:
      return "OK";
    case StatusLevel::kWarn:
      return "WARN";
    case StatusLevel::kError:
      return "ERROR";
    case StatusLevel::kStale:
      return "STALE";
  }
  return "?";
}

void StatusReport::summary(StatusLevel new_level, std::string new_message) {
  level = new_level;
  message = std::move(new_message);
}

void StatusReport::mergeSummary(StatusLevel other_level, const std::string& other_message) {
  if (other_level > StatusLevel::kOk && level > StatusLevel::kOk) {
    if (!message.empty()) message += "; ";
    message += other_message;
  } else if (other_level > level) {
    message = other_message;
  }
  if (other_level > level) level = other_level;
}

void StatusReport::mergeSummaryf(StatusLevel other_level, const char* format, ...) {
  va_list args;
  va_start(args, format);
  const std::string text = vformat(format, args);
  va_end(args);
  mergeSummary(other_level, text);
}

void StatusReport::add(std::string key, std::string value) {
  values.emplace_back(std::move(key), std::move(value));
}

void StatusReport::addf(std::string key, const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::string text = vformat(format, args);
  va_end(args);
  add(std::move(key), std::move(text));
}

const std::string* StatusReport::find(const std::string& key) const {
  for (const auto& [name, value] : values) {
    if (name == key) return &value;
  }
  return nullptr;
}

}  // namespace serial_robot_driver::core
