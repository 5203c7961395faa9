// The wire capture's diagnostic status ("wire capture", ~capture): the chunks published on
// serial_raw and, above all, any that were dropped because the subscribers fell behind.
#pragma once

#include <cstddef>
#include <cstdint>

#include "serial_robot_driver/core/status_report.h"

namespace serial_robot_driver::core {

struct WireCaptureStats {
  uint64_t chunks = 0;        ///< published: handed to roscpp, which queues it for every subscriber
  uint64_t bytes = 0;         ///< in published chunks
  uint64_t dropped = 0;       ///< chunks lost to the capture's full queue (ros/wire_capture.h)
  std::size_t queued = 0;     ///< waiting in the capture's queue now
  std::size_t in_roscpp = 0;  ///< published chunks roscpp still holds unsent (some subscriber)
};

/// OK while every chunk was published, WARN once one was dropped.
StatusReport wireCaptureStatus(const WireCaptureStats& stats);

}  // namespace serial_robot_driver::core
