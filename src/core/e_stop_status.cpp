#include "serial_robot_driver/core/e_stop_status.h"

#include "serial_robot_driver/core/log.h"

namespace serial_robot_driver::core {

StatusReport eStopStatus(const EStopStats& stats) {
  StatusReport status;
  if (stats.engaged) {
    status.summary(StatusLevel::kWarn, "engaged: every actuator stopped, motion commands refused");
  } else {
    status.summary(StatusLevel::kOk, "released");
  }
  status.add(kEStopEngagedKey, stats.engaged);
  status.add(kEStopEngagementsKey, stats.engagements);
  uint64_t refused = 0;
  for (const auto& [source, count] : stats.refused) {
    status.add("refused: " + source, count);
    refused += count;
  }
  status.add("commands refused", refused);
  return status;
}

void logEStopChange(bool engaged) {
  if (engaged) {
    log(LogLevel::kWarn,
        "e_stop engaged: every actuator stopped (base at zero speed, trajectories aborted, bus "
        "servos stopped); motion commands refused until e_stop is false");
  } else {
    log(LogLevel::kInfo, "e_stop released: motion commands obeyed from the next one");
  }
}

}  // namespace serial_robot_driver::core
