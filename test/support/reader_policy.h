// The scheduling a SerialLink's reader thread really runs at (~realtime_priority,
// ~scheduler_slice_us): a link on a pty of its own, its policy noted by the reader thread itself
// when the link comes up.
#pragma once

#include <unistd.h>

#include <atomic>
#include <functional>
#include <string>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "support/framer_configs.h"
#include "support/realtime_support.h"
#include "support/test_helpers.h"

namespace test_support {

/// Notes the policy of the thread that calls onLinkUp: the link's reader thread.
class PolicyListener : public serial_robot_driver::core::LinkListener {
 public:
  void onLinkUp() override {
    policy = currentThreadPolicy();
    up = true;
  }
  void onFrame(serial_robot_driver::protocol::FrameFamily, const uint8_t*, std::size_t,
               serial_robot_driver::core::Clock::time_point) override {}
  ThreadPolicy policy;
  std::atomic<bool> up{false};
};

/// The reader thread's policy of a base link whose options `configure` sets; a default
/// ThreadPolicy (policy -1) when the link did not come up within 3 s.
inline ThreadPolicy readerThreadPolicy(
    const std::function<void(serial_robot_driver::core::SerialLinkOptions&)>& configure) {
  const std::string path = "/tmp/srd_reader_policy_test_" + std::to_string(::getpid());
  serial_robot_driver::sim::PseudoTerminal pty(path);
  serial_robot_driver::core::SerialLinkOptions options;
  options.path = path;
  options.framer = driverFramer({"base"}, 2);
  configure(options);
  serial_robot_driver::core::SerialLink link(options);
  PolicyListener listener;
  link.addListener(&listener);
  link.start();
  const bool up = waitFor([&] { return listener.up.load(); }, 3.0);
  link.stop();
  return up ? listener.policy : ThreadPolicy{};
}

}  // namespace test_support
