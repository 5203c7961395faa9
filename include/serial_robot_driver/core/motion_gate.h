// Whether a motion frame may be written, decided at the moment it is written: a device writes
// each motion frame through its gate, under the gate's lock, and the e-stop (setLocked) and the
// shutdown (close) take that same lock. So once setLocked(true) or close() has returned, no motion
// frame is written, however long it waited for the bus before its turn came. Stop frames do not
// go through a gate: a stop is always let through. ROS-free.
//
// An e-stop voids everything accepted before it, even once released (a reset never restarts
// motion by itself): each engagement starts a new generation; a command notes generation() when
// it is accepted and hands it to writeIfOpen(), which drops it (kVoided) when an e-stop engaged
// since, whether or not it still holds.
//
// Threading: any thread. writeIfOpen() holds the lock only around the write itself (one frame
// into the port, never a wait for an answer), so setLocked() waits microseconds at most.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>

namespace serial_robot_driver::core {

enum class GateState {
  kOpen,    ///< motion frames are written
  kLocked,  ///< the e-stop is engaged
  kClosed,  ///< the device is shutting down: for good
  kVoided,  ///< open, but the e-stop engaged after the command was accepted: dropped
};
const char* toString(GateState state);

class MotionGate {
 public:
  /// Counts the e-stop's engagements: a command accepted under one generation never moves
  /// anything under a later one.
  using Generation = uint64_t;

  /// The e-stop engaged (true) or released (false). A closed gate stays closed.
  void setLocked(bool locked);
  /// From now on nothing passes, for good (the device's last words are being decided).
  void close();
  GateState state() const;
  /// The generation a command accepted now belongs to (note it before waiting for the wire).
  /// Lock-free: callers note it while holding locks of their own that the gate's writer may take
  /// (the servo bus's bookkeeping), so taking the gate's lock here could invert their order.
  Generation generation() const { return generation_.load(); }

  /// Runs `write` (one motion frame onto the wire; returns whether it went out) only while the
  /// gate is open and, given `accepted`, no e-stop engaged since that generation, with the gate's
  /// lock held. Returns the state that decided: kOpen when `write` ran, with its outcome in
  /// `*written`; otherwise nothing was written and the refusal is counted.
  GateState writeIfOpen(const std::function<bool()>& write, bool* written,
                        std::optional<Generation> accepted = std::nullopt);
  /// Motion frames refused by writeIfOpen() (accepted earlier, refused when their turn came).
  uint64_t refusedAtWrite() const;

 private:
  GateState stateLocked() const;

  mutable std::mutex mutex_;
  bool locked_ = false;
  bool closed_ = false;
  std::atomic<Generation> generation_{0};  // engagements so far; changed under mutex_
  uint64_t refused_ = 0;
};

}  // namespace serial_robot_driver::core
