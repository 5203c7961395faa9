// ROS-free helpers shared by the unit tests and rostests: polling with a deadline, byte vectors.
//
// Header-only: the unit tests use it without linking the rostests' support library.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <thread>
#include <vector>

namespace test_support {

using Clock = std::chrono::steady_clock;
using Bytes = std::vector<uint8_t>;

inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Polls `done` every 10 ms until it holds or `timeout_s` has passed. The timeouts in the tests
/// are generous upper bounds for a busy machine, never the quantity under test.
inline bool waitFor(const std::function<bool()>& done, double timeout_s) {
  const Clock::time_point start = Clock::now();
  while (!done()) {
    if (secondsSince(start) > timeout_s) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

inline void sleepSeconds(double seconds) {
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

/// The frames one after the other, as they would arrive on a wire.
inline Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes all;
  for (const Bytes& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

/// A copy of `frame` with one byte replaced (a corrupted checksum, length or tail).
inline Bytes withByte(Bytes frame, std::size_t index, uint8_t value) {
  frame.at(index) = value;
  return frame;
}

}  // namespace test_support
