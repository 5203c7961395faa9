#include "serial_robot_driver/core/input_refusals.h"

namespace serial_robot_driver::core {

namespace {

void addCounts(const std::map<std::string, uint64_t>& counts, const std::string& what,
               StatusReport& status) {
  uint64_t total = 0;
  for (const auto& [source, count] : counts) {
    status.add(what + ": " + source, count);
    total += count;
  }
  status.add(what, total);
}

}  // namespace

InputRefusalStats& InputRefusalStats::operator+=(const InputRefusalStats& other) {
  for (const auto& [source, count] : other.refused) refused[source] += count;
  for (const auto& [source, count] : other.errors) errors[source] += count;
  return *this;
}

void InputRefusals::refused(const std::string& source) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.refused[source];
}

void InputRefusals::failed(const std::string& source) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.errors[source];
}

InputRefusalStats InputRefusals::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void addInputRefusals(const InputRefusalStats& stats, StatusReport& status) {
  addCounts(stats.refused, "inputs refused", status);
  addCounts(stats.errors, "callback errors", status);
}

}  // namespace serial_robot_driver::core
