#include "serial_robot_driver/core/loop_clock.h"

namespace serial_robot_driver::core {

namespace {
class SteadyLoopClock : public LoopClock {
 public:
  Clock::time_point now() const override { return Clock::now(); }
  void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& wake,
                 Clock::time_point deadline) override {
    wake.wait_until(lock, deadline);
  }
  void waitUntil(std::unique_lock<std::mutex>& lock, LoopWake& wake,
                 Clock::time_point deadline) override {
    wake.waitUntil(lock, deadline);
  }
};
}  // namespace

std::shared_ptr<LoopClock> steadyLoopClock() { return std::make_shared<SteadyLoopClock>(); }

}  // namespace serial_robot_driver::core
