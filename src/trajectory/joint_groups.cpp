#include "serial_robot_driver/trajectory/joint_groups.h"

#include <chrono>

namespace serial_robot_driver::trajectory {

double steadyNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::optional<double> streamedHoldPosition(std::optional<double> last_written,
                                           std::optional<double> last_commanded,
                                           std::optional<double> fresh_measurement) {
  if (last_written) return last_written;
  if (last_commanded) return last_commanded;
  return fresh_measurement;
}

}  // namespace serial_robot_driver::trajectory
