// The core's log lines (core/log.h) kept for a test's checks while it lives.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include "serial_robot_driver/core/log.h"

namespace test_support {

class LogCapture {
 public:
  LogCapture() {
    serial_robot_driver::core::setLogSink(
        [this](serial_robot_driver::core::LogLevel, const std::string& text) {
          std::lock_guard<std::mutex> lock(mutex_);
          lines_.push_back(text);
        });
  }
  ~LogCapture() { serial_robot_driver::core::setLogSink({}); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;

  /// The lines that contain `part`.
  std::size_t count(const std::string& part) const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t found = 0;
    for (const std::string& line : lines_) found += line.find(part) != std::string::npos ? 1 : 0;
    return found;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
};

}  // namespace test_support
