// A value replaced whole at runtime (a retune from dynamic_reconfigure's thread) and read by a hot
// thread once per frame or tick. The hot thread keeps its own reference to the value in force and
// reads one counter per frame; only after a swap does it take the lock and the new reference. (A
// std::atomic_load of a shared_ptr takes a mutex of libstdc++'s shared pool and writes the
// reference count's cache line on every read.)
//
// Threading: set() and get() from any thread. A Reader belongs to one thread at a time: its
// current() is never called concurrently with itself, and the reference it returns stays valid
// until that Reader's next current().
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>

namespace serial_robot_driver::core {

template <typename T>
class SwappedValue {
 public:
  explicit SwappedValue(std::shared_ptr<const T> initial) : value_(std::move(initial)) {}

  /// `next` is in force from every Reader's next current() on.
  void set(std::shared_ptr<const T> next) {
    std::lock_guard<std::mutex> lock(mutex_);
    value_ = std::move(next);
    version_.fetch_add(1, std::memory_order_release);
  }
  std::shared_ptr<const T> get() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return value_;
  }

  class Reader {
   public:
    explicit Reader(const SwappedValue& source) : source_(source) { refresh(); }
    /// The value in force; the one it replaced stays alive (for this thread) until the next call.
    const T& current() {
      if (source_.version_.load(std::memory_order_acquire) != version_) refresh();
      return *value_;
    }

   private:
    void refresh() {
      std::lock_guard<std::mutex> lock(source_.mutex_);
      value_ = source_.value_;
      version_ = source_.version_.load(std::memory_order_relaxed);
    }
    const SwappedValue& source_;
    std::shared_ptr<const T> value_;
    uint64_t version_ = 0;
  };

 private:
  mutable std::mutex mutex_;  // guards value_; version_ changes only under it
  std::shared_ptr<const T> value_;
  std::atomic<uint64_t> version_{0};
};

}  // namespace serial_robot_driver::core
