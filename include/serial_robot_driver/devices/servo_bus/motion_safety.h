// A device::ServoBus's motion policy: what may be written (the motion gate, the e-stop, a servo
// protect keeps relaxed), which servos the driver set moving or positioned, so the e-stop and the
// shutdown stop exactly those (their stops kept until confirmed by the StopKeeper,
// stop_keeper.h), and the last words at shutdown. ROS-free.
//
// Threading: any thread. The motion operations run on their caller's thread. Every motion frame,
// whoever writes it, passes the gate when it is written: the e-stop (setMotionLocked) and the
// shutdown (closeGate) take the gate's lock, so no motion frame goes out after they return,
// however long it waited for the bus. The bookkeeping is guarded by the bus's one mutex (given at
// construction), which the methods named ...Locked expect held; the bus is called without it.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <set>
#include <vector>

#include "serial_robot_driver/device/loop_clock.h"
#include "serial_robot_driver/device/motion_gate.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_config.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_events.h"
#include "serial_robot_driver/devices/servo_bus/servo_poller.h"
#include "serial_robot_driver/devices/servo_bus/stop_keeper.h"

namespace serial_robot_driver::device {

class MotionSafety {
 public:
  /// How long finalWords() keeps writing and confirming its stops, at most.
  static constexpr std::chrono::milliseconds kShutdownStopBudget{1000};

  struct Hooks {
    /// The e-stop engaged (mutex held): no queued move may go out.
    std::function<void()> drop_queued_moves_locked;
    /// Stops were armed (mutex released): have them written (StopKeeper) without waiting.
    std::function<void()> deliver_stops;
  };

  /// `settings`: the bus's settings in force, guarded by `mutex`. `polled_ids`: the servos
  /// relax() and hold() mean when given none.
  MotionSafety(const std::vector<uint8_t>& polled_ids, const ServoBusConfig& settings,
               ServoBusClient& client, const ServoBusEvents& events, LoopClock& clock,
               std::mutex& mutex, StopKeeper& stops, const ServoPoller& poller, Hooks hooks);

  // The client's motion operations, refused (kMotionRefused) while the e-stop holds or protect
  // keeps the servo relaxed, and noted (see ServoBus).
  ServoStatus move(const MoveRequest& request);
  ServoStatus rotate(const RotateRequest& request);
  ServoStatus spin(const SpinRequest& request);
  ServoStatus damping(uint8_t id, uint16_t power_mw, bool wait);
  ServoStatus relax(const std::vector<uint8_t>& ids);
  ServoStatus hold(const std::vector<uint8_t>& ids);
  /// Why servo `id` may not move now (the e-stop, protect); ok when it may.
  ServoStatus refusal(uint8_t id) const;
  /// A motion frame of servo `id` went out (told by the client under the gate's lock, so an
  /// e-stop engaged right after it finds the servo among those to stop). A pending stop of the
  /// servo (a hold's) is superseded.
  void noteCommanded(uint8_t id);
  /// Notes the outcome of a motion command of servo `id`: moving or at rest.
  void noteMotion(uint8_t id, bool moving);
  /// The stop of `id` went out (StopKeeper, mutex held): it is no longer set moving.
  void noteStopWrittenLocked(uint8_t id);

  /// The e-stop (see ServoBus::setMotionLocked).
  void setMotionLocked(bool locked);
  bool motionLocked() const;
  bool motionLockedLocked() const { return motion_locked_; }
  /// A reconnect: the e-stop's stops and every kept one are written again first. Whether any
  /// stop is kept.
  bool rearmStopsLocked(Clock::time_point now);
  std::vector<uint8_t> movingIds() const;
  std::vector<uint8_t> commandedIds() const;

  MotionGate& gate() { return gate_; }
  uint64_t refusedAtWrite() const { return gate_.refusedAtWrite(); }
  /// From now on no motion frame passes, for good (the last words are being decided).
  void closeGate() { gate_.close(); }
  /// Says the last words (settings' on_shutdown) to the servos set moving, on the caller's
  /// thread after the worker has stopped, each stop confirmed for at most kShutdownStopBudget.
  /// Once.
  void finalWords();

 private:
  ServoStatus refusalLocked(uint8_t id) const;

  const std::vector<uint8_t> polled_ids_;
  const ServoBusConfig& settings_;
  ServoBusClient& client_;
  const ServoBusEvents& events_;
  LoopClock& clock_;
  std::mutex& mutex_;  // the bus's: guards everything below but the gate
  StopKeeper& stops_;
  const ServoPoller& poller_;
  const Hooks hooks_;
  MotionGate gate_;              // every motion frame passes it when written; its own lock
  std::set<uint8_t> commanded_;  // set moving or positioned since start-up
  std::set<uint8_t> moving_;     // servos set moving and not stopped since
  bool motion_locked_ = false;
  bool final_words_said_ = false;
};

}  // namespace serial_robot_driver::device
