#include "serial_robot_driver/core/log.h"

#include <cstdarg>
#include <cstdio>
#include <memory>
#include <utility>

namespace serial_robot_driver::core {

namespace {

const char* levelName(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "DEBUG";
    case LogLevel::kInfo:
      return "INFO";
    case LogLevel::kWarn:
      return "WARN";
    case LogLevel::kError:
      return "ERROR";
  }
  return "?";
}

void writeToStderr(LogLevel level, const std::string& text) {
  if (level == LogLevel::kDebug) return;
  std::fprintf(stderr, "[%s] %s\n", levelName(level), text.c_str());
}

/// Swapped whole (std::atomic_load/store), so a line logged while the sink is set never sees half
/// a function.
std::shared_ptr<const LogSink>& sinkSlot() {
  static std::shared_ptr<const LogSink> sink = std::make_shared<const LogSink>(writeToStderr);
  return sink;
}

}  // namespace

void setLogSink(LogSink sink) {
  std::atomic_store(&sinkSlot(), std::make_shared<const LogSink>(sink ? std::move(sink)
                                                                      : LogSink(writeToStderr)));
}

void log(LogLevel level, const char* format, ...) {
  char text[1024];
  va_list arguments;
  va_start(arguments, format);
  std::vsnprintf(text, sizeof text, format, arguments);
  va_end(arguments);
  const std::shared_ptr<const LogSink> sink = std::atomic_load(&sinkSlot());
  (*sink)(level, text);
}

bool LogThrottle::pass() {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(mutex_);
  if (last_ && now - *last_ < period_) return false;
  last_ = now;
  return true;
}

}  // namespace serial_robot_driver::core
