// A device::ServoBus's motion policy: what may be written (the motion gate, the e-stop, a servo
// protect keeps relaxed), which servos the driver set moving or positioned, so the e-stop and the
// shutdown stop exactly those (their stops kept until confirmed by the StopKeeper,
// stop_keeper.h), and the last words at shutdown. ROS-free.
//
// The rules:
//  - An e-stop voids everything accepted before it. Each motion (move, rotate, spin, hold, a
//    queued move) notes the gate's generation when it is accepted, before it waits for the bus,
//    and is written with it: an e-stop engaged since drops it at the write, even once released
//    (kMotionRefused, "e-stop engaged after this command was accepted").
//  - Broadcast motions (id 255) are refused: nothing answers them, so the driver could not tell
//    which servos they set moving nor confirm their stops. A broadcast SPIN stop or DAMPING is
//    allowed.
//  - Torque off (damping, relax) is a safety action: allowed while the e-stop holds, never held
//    back by the gate. A servo relaxed by its id leaves the servos to stop: its kept stop is
//    satisfied and no longer repeated (a SPIN stop would give it its holding torque back).
//  - Writes that change where or how a servo moves, or where its stop goes (servo_id, baudrate,
//    response_switch, stall protection, accel_switch, angle limits, mid offset) and
//    RESET_USER_DATA are refused while the e-stop holds or while that servo moves (set moving
//    and not stopped or relaxed since, or its stop not yet confirmed). An address change that is
//    allowed takes the servo's bookkeeping (set moving, commanded, kept stop) to its new id.
//  - While the e-stop holds, its stops are written again at a steady pace (StopKeeper::
//    kStopRepeat); releasing it ends that, and keeps the stops never written.
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
#include <string>
#include <string_view>
#include <vector>

#include "serial_robot_driver/core/loop_clock.h"
#include "serial_robot_driver/core/motion_gate.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_config.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_events.h"
#include "serial_robot_driver/devices/servo_bus/servo_poller.h"
#include "serial_robot_driver/devices/servo_bus/stop_keeper.h"

namespace serial_robot_driver::devices::servo_bus {

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
               ServoBusClient& client, const ServoBusEvents& events, core::LoopClock& clock,
               std::mutex& mutex, StopKeeper& stops, const ServoPoller& poller, Hooks hooks);

  // The client's motion operations, refused (kMotionRefused) while the e-stop holds or protect
  // keeps the servo relaxed, and noted (see ServoBus).
  ServoStatus move(const MoveRequest& request);
  ServoStatus rotate(const RotateRequest& request);
  ServoStatus spin(const SpinRequest& request);
  ServoStatus damping(uint8_t id, uint16_t power_mw, bool wait);
  ServoStatus relax(const std::vector<uint8_t>& ids);
  ServoStatus hold(const std::vector<uint8_t>& ids);
  /// The client's WRITE_DATA and RESET_USER_DATA under the rules above.
  ServoStatus writeParam(uint8_t id, std::string_view param, int64_t value);
  ServoStatus resetUserData(uint8_t id);
  /// Why servo `id` may not move now (the e-stop, protect); ok when it may.
  ServoStatus refusal(uint8_t id) const;
  /// Whether servo `id` may be set moving now (refusal(), and no broadcast), and the generation
  /// the command is accepted under: noted before the e-stop is looked at, so an e-stop engaged
  /// in between either refuses the command here or voids it at the write.
  ServoStatus accept(uint8_t id, core::MotionGate::Generation* generation) const;
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
  bool rearmStopsLocked(core::Clock::time_point now);
  std::vector<uint8_t> movingIds() const;
  std::vector<uint8_t> commandedIds() const;

  core::MotionGate& gate() { return gate_; }
  uint64_t refusedAtWrite() const { return gate_.refusedAtWrite(); }
  /// From now on no motion frame passes, for good (the last words are being decided).
  void closeGate() { gate_.close(); }
  /// Says the last words (settings' on_shutdown) to the servos set moving, on the caller's
  /// thread after the worker has stopped, each stop confirmed for at most kShutdownStopBudget.
  /// Once.
  void finalWords();

 private:
  ServoStatus refusalLocked(uint8_t id) const;
  /// Why a write that changes how or where servo `id` moves (`what`) may not go out now.
  ServoStatus settingRefusal(uint8_t id, const std::string& what) const;
  /// Servo `from` now answers at `to`: what the driver knows of it follows.
  void followAddress(uint8_t from, uint8_t to);

  const std::vector<uint8_t> polled_ids_;
  const ServoBusConfig& settings_;
  ServoBusClient& client_;
  const ServoBusEvents& events_;
  core::LoopClock& clock_;
  std::mutex& mutex_;  // the bus's: guards everything below but the gate
  StopKeeper& stops_;
  const ServoPoller& poller_;
  const Hooks hooks_;
  core::MotionGate gate_;        // every motion frame passes it when written; its own lock
  std::set<uint8_t> commanded_;  // set moving or positioned since start-up
  std::set<uint8_t> moving_;     // servos set moving and not stopped since
  bool motion_locked_ = false;
  bool final_words_said_ = false;
};

}  // namespace serial_robot_driver::devices::servo_bus
