// The stops a device::ServoBus keeps until each is known to have reached its servo: written as
// urgent work on the bus (after the one transaction attempt in flight, before every waiting call,
// scan id or poll), then the servo seen at rest by two angle reads kStopSettle apart. A stop that
// could not be written, after which the servo did not answer, or that left it moving is written
// again. Which servos are to be stopped, and when, is MotionSafety's (motion_safety.h). ROS-free.
//
// The rule of rest, and why it does not stand alone: two reads kStopSettle apart that differ by
// no more than kRestToleranceDeg cannot tell rest from a motion slower than about
// kRestToleranceDeg / kStopSettle (5 deg/s: a slow ROTATE or SPIN whose stop was lost). So a
// stop armed while the e-stop holds (`repeat`) is not done when its servo is seen at rest: it is
// written again every kStopRepeat for as long as the e-stop holds (a SPIN stop to a servo at rest
// is harmless), so a servo still turning, however slowly, is stopped within kStopRepeat of the
// first stop that reaches it. Only the first confirmation is reported; a repeated stop seen at
// rest once is no longer listed as pending. Released (releaseLocked), a stop that went out is
// done, one never written (the port was down all along) is kept and goes out once it can.
//
// Threading: the state is guarded by the bus's one mutex (given at construction), which the
// methods named ...Locked expect held. The work runs on the bus's worker thread (StopPace::
// kScheduled), or back to back on the caller's (kNow: before start(), at shutdown). The bus and
// the hooks are called with the mutex released.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/loop_clock.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_events.h"

namespace serial_robot_driver::devices::servo_bus {

/// How stop work is paced: by the bus's clock (the worker), or back to back with real sleeps for
/// the settle (on the caller's thread, whatever clock the bus has).
enum class StopPace { kScheduled, kNow };

class StopKeeper {
 public:
  /// A stopped servo's angle is read twice this far apart; it is at rest when it moved no more
  /// than kRestToleranceDeg meanwhile.
  static constexpr std::chrono::milliseconds kStopSettle{100};
  static constexpr double kRestToleranceDeg = 0.5;
  /// A stop that could not be written is tried again after this; a reconnect tries it at once.
  static constexpr std::chrono::milliseconds kStopRetry{100};
  /// While the e-stop holds, each of its stops is written again this often (see above).
  static constexpr std::chrono::milliseconds kStopRepeat{500};

  /// `on_written_locked`: the stop of `id` went out (mutex held): it is no longer set moving.
  StopKeeper(ServoBusClient& client, const ServoBusEvents& events, core::LoopClock& clock,
             std::mutex& mutex, std::function<void(uint8_t id)> on_written_locked);

  /// Adds a stop of `id` to be written now, or has a kept one written again now (and seen at
  /// rest again). `repeat`: the e-stop's, written again every kStopRepeat even once at rest.
  void armLocked(uint8_t id, core::Clock::time_point now, bool repeat = false);
  /// Every kept stop is written again now (a reconnect).
  void rearmAllLocked(core::Clock::time_point now);
  /// The servo needs no stop any more (a later motion superseded it, or it was relaxed).
  void eraseLocked(uint8_t id) { stops_.erase(id); }
  /// The e-stop released: the stops that went out are done and none is repeated any more; one
  /// never written is kept until it is written and seen at rest.
  void releaseLocked();
  /// No stop is repeated any more; each ends once seen at rest (the last words).
  void endRepeatsLocked();
  /// Servo `from` now answers at `to` (an address change): its stop follows it.
  void renameLocked(uint8_t from, uint8_t to);
  bool emptyLocked() const { return stops_.empty(); }
  bool keptLocked(uint8_t id) const { return stops_.count(id) > 0; }
  /// Whether the last write of every kept stop failed (the port is down).
  bool portDownLocked() const;
  /// The stops not confirmed yet, with what is still missing.
  std::vector<std::pair<uint8_t, std::string>> unconfirmedLocked() const;
  /// Stops not yet known to have reached their servo (for diagnostics).
  std::vector<PendingStopReport> reports() const;

  /// Reserves the bus for the stops (ServoBusClient::requestUrgent) until endUrgentLocked().
  /// Takes the mutex.
  void askUrgent();
  void endUrgentLocked();
  /// When the stop work falls due next; min() while the bus is reserved, max() when none.
  core::Clock::time_point nextWorkLocked() const;
  /// One piece of stop work that is due (mutex held by `lock`, released around the bus): every
  /// stop to be written, or one look at a stopped servo. False when nothing was due.
  bool workOnce(std::unique_lock<std::mutex>& lock, StopPace pace);
  /// Writes every stop due (all of them with kNow).
  void writeDue(std::unique_lock<std::mutex>& lock, StopPace pace);

 private:
  /// A stop until the servo is seen at rest.
  struct PendingStop {
    enum class Phase { kWrite, kFirstLook, kSecondLook } phase = Phase::kWrite;
    core::Clock::time_point due;
    double first_angle = 0.0;
    int written = 0;
    bool repeat = false;     ///< the e-stop's: written again every kStopRepeat while it holds
    bool at_rest = false;    ///< a repeated stop seen at rest once: no longer pending
    bool port_down = false;  ///< the last write failed
    std::string why = "not written yet";
  };

  void lookAtStoppedServo(std::unique_lock<std::mutex>& lock, uint8_t id, StopPace pace);
  /// The second look found the servo at rest: the stop is done, or repeated (the e-stop's).
  ServoStatus seenAtRestLocked(std::map<uint8_t, PendingStop>::iterator it, double angle_deg,
                               core::Clock::time_point now);

  ServoBusClient& client_;
  const ServoBusEvents& events_;
  core::LoopClock& clock_;
  std::mutex& mutex_;  // the bus's: guards everything below
  const std::function<void(uint8_t id)> on_written_locked_;
  std::map<uint8_t, PendingStop> stops_;  // not yet known to have reached their servo
  bool urgent_asked_ = false;             // askUrgent() .. endUrgentLocked()
};

}  // namespace serial_robot_driver::devices::servo_bus
