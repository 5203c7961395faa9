#include "serial_robot_driver/core/wire_capture_status.h"

namespace serial_robot_driver::core {

StatusReport wireCaptureStatus(const WireCaptureStats& s) {
  StatusReport status;
  if (s.dropped > 0) {
    status.summary(StatusLevel::kWarn, "chunks dropped: the subscribers fell behind");
  } else {
    status.summary(StatusLevel::kOk, "capturing on serial_raw");
  }
  status.add("chunks published", s.chunks);
  status.add("bytes published", s.bytes);
  status.add("chunks dropped", s.dropped);
  status.add("chunks queued", s.queued);
  status.add("chunks held by roscpp", s.in_roscpp);
  return status;
}

}  // namespace serial_robot_driver::core
