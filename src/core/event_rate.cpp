#include "serial_robot_driver/core/event_rate.h"

#include <cmath>
#include <utility>

namespace serial_robot_driver::core {

EventRate::EventRate(double min_hz, double max_hz, Clock clock)
    : min_hz_(min_hz), max_hz_(max_hz), clock_(std::move(clock)) {
  times_.fill(clock_());
}

void EventRate::tick() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++count_;
}

void EventRate::addTo(StatusReport& report) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double now = clock_();
  const int events = count_ - counts_[slot_];
  const double window = now - times_[slot_];
  const double hz = window != 0 ? events / window : 0.0;
  counts_[slot_] = count_;
  times_[slot_] = now;
  slot_ = (slot_ + 1) % kWindow;

  if (events == 0) {
    report.summary(StatusLevel::kError, "No events recorded.");
  } else if (window != 0 && hz < min_hz_ * (1 - kTolerance)) {
    report.summary(StatusLevel::kWarn, "Frequency too low.");
  } else if (window != 0 && hz > max_hz_ * (1 + kTolerance)) {
    report.summary(StatusLevel::kWarn, "Frequency too high.");
  } else if (window != 0) {
    report.summary(StatusLevel::kOk, "Desired frequency met");
  }
  report.addf("Events in window", "%d", events);
  report.addf("Events since startup", "%d", count_);
  report.addf("Duration of window (s)", "%f", window);
  if (window != 0) report.addf("Actual frequency (Hz)", "%f", hz);
  if (min_hz_ == max_hz_) report.addf("Target frequency (Hz)", "%f", min_hz_);
  if (min_hz_ > 0)
    report.addf("Minimum acceptable frequency (Hz)", "%f", min_hz_ * (1 - kTolerance));
  if (std::isfinite(max_hz_)) {
    report.addf("Maximum acceptable frequency (Hz)", "%f", max_hz_ * (1 + kTolerance));
  }
}

}  // namespace serial_robot_driver::core
