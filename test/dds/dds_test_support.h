#pragma once
// Shared by the DDS runtime tests (test/dds, test/dds_front, the ROS 2 rostest, dds_bench): a
// domain id of this test process's own, condition waits.

#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace dds_test {

/// A domain no other test process of the suite uses at the same time (ports differ per domain).
inline int privateDomainId(int first, int count) {
  return first + static_cast<int>(getpid()) % count;
}

/// Waits until `done` holds; false if it still does not after `deadline` (generous: no timing is
/// asserted, only that the condition comes true).
inline bool waitFor(const std::function<bool()>& done,
                    std::chrono::seconds deadline = std::chrono::seconds(30)) {
  const auto give_up = std::chrono::steady_clock::now() + deadline;
  while (!done()) {
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

/// Values handed over from a callback thread.
template <typename T>
class Mailbox {
 public:
  void put(const T& value) {
    std::lock_guard<std::mutex> lock(mutex_);
    values_.push_back(value);
    changed_.notify_all();
  }
  /// Waits for at least `count` values.
  bool waitForCount(size_t count, std::chrono::seconds deadline = std::chrono::seconds(20)) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, deadline, [&] { return values_.size() >= count; });
  }
  std::vector<T> values() {
    std::lock_guard<std::mutex> lock(mutex_);
    return values_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<T> values_;
};

}  // namespace dds_test
