// Whether a motion frame may be written, decided at the moment it is written: a device writes
// each motion frame through its gate, under the gate's lock, and the e-stop (setLocked) and the
// shutdown (close) take that same lock. So once setLocked(true) or close() has returned, no motion
// frame is written, however long it waited for the bus before its turn came. Stop frames do not
// go through a gate: a stop is always let through. ROS-free.
//
// Threading: any thread. writeIfOpen() holds the lock only around the write itself (one frame
// into the port, never a wait for an answer), so setLocked() waits microseconds at most.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>

namespace serial_robot_driver::device {

enum class GateState {
  kOpen,    ///< motion frames are written
  kLocked,  ///< the e-stop is engaged
  kClosed,  ///< the device is shutting down: for good
};
const char* toString(GateState state);

class MotionGate {
 public:
  /// The e-stop engaged (true) or released (false). A closed gate stays closed.
  void setLocked(bool locked);
  /// From now on nothing passes, for good (the device's last words are being decided).
  void close();
  GateState state() const;

  /// Runs `write` (one motion frame onto the wire; returns whether it went out) only while the
  /// gate is open, with the gate's lock held. Returns the state that decided: kOpen when `write`
  /// ran, with its outcome in `*written`; otherwise nothing was written and the refusal is counted.
  GateState writeIfOpen(const std::function<bool()>& write, bool* written);
  /// Motion frames refused by writeIfOpen() (accepted earlier, refused when their turn came).
  uint64_t refusedAtWrite() const;

 private:
  GateState stateLocked() const;

  mutable std::mutex mutex_;
  bool locked_ = false;
  bool closed_ = false;
  uint64_t refused_ = 0;
};

}  // namespace serial_robot_driver::device
