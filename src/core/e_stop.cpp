#include "serial_robot_driver/core/e_stop.h"

#include <utility>

namespace serial_robot_driver::core {

void EStop::addListener(Listener listener) { listeners_.push_back(std::move(listener)); }

bool EStop::set(bool engaged) {
  std::lock_guard<std::mutex> lock(set_mutex_);
  if (engaged_.exchange(engaged) == engaged) return false;
  {
    std::lock_guard<std::mutex> state(state_mutex_);
    stats_.engaged = engaged;
    if (engaged) ++stats_.engagements;
  }
  for (const Listener& listener : listeners_) listener(engaged);
  return true;
}

bool EStop::refuse(const std::string& source) {
  if (!engaged_.load()) return false;
  std::lock_guard<std::mutex> state(state_mutex_);
  ++stats_.refused[source];
  return true;
}

EStopStats EStop::stats() const {
  std::lock_guard<std::mutex> state(state_mutex_);
  return stats_;
}

}  // namespace serial_robot_driver::core
