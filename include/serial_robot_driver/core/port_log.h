// A port's comings and goings in the core's log (core/log.h), once per event, and the USB latency
// hint. Once the driver shuts down, a port going down is the driver closing it (or the robot's end
// going at the same moment): stopping is not losing, so nothing is logged as lost.
#pragma once

#include <atomic>
#include <string>

#include "serial_robot_driver/core/serial_link.h"

namespace serial_robot_driver::core {

class PortLog : public LinkListener {
 public:
  /// Listens to nothing yet: `link.addListener(this)` before the link starts. `shutting_down`
  /// must outlive this.
  PortLog(const SerialLink& link, const std::atomic<bool>& shutting_down)
      : link_(link), shutting_down_(shutting_down) {}

  void onLinkUp() override;
  void onLinkDown() override;
  void onOpenFailed(const std::string& error) override;
  void onFrame(protocol::FrameFamily, const uint8_t*, std::size_t, Clock::time_point) override {}

 private:
  const SerialLink& link_;
  const std::atomic<bool>& shutting_down_;
  bool waiting_logged_ = false;  // reader thread only
};

}  // namespace serial_robot_driver::core
