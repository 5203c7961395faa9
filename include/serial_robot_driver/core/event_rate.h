// How often an event happens (a frame arrives), checked against an acceptable range each time a
// status is asked for: diagnostic_updater's FrequencyStatus in core values, with the same window
// (the events since the call five calls ago), tolerance, summaries and keys, so a front end's
// status reads as it always did.
//
// Threading: tick() on the event's thread, addTo() on the status thread; one mutex orders them.
#pragma once

#include <array>
#include <functional>
#include <mutex>

#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

class EventRate {
 public:
  /// Seconds on the clock the window is measured with (the front end's: ROS time in the node).
  using Clock = std::function<double()>;
  /// Acceptable: min_hz * 0.9 .. max_hz * 1.1 (max_hz infinite: no upper bound).
  EventRate(double min_hz, double max_hz, Clock clock);

  /// One event.
  void tick();
  /// Sets `report`'s summary from the rate over the window (no events: ERROR; outside the range:
  /// WARN; else OK) and adds its keys; then starts the next window slot.
  void addTo(StatusReport& report);

 private:
  static constexpr int kWindow = 5;
  static constexpr double kTolerance = 0.1;
  const double min_hz_;
  const double max_hz_;
  const Clock clock_;
  std::mutex mutex_;
  int count_ = 0;
  std::array<double, kWindow> times_{};
  std::array<int, kWindow> counts_{};
  int slot_ = 0;
};

}  // namespace serial_robot_driver::core
