// The UART servo bus as a device: the owner that wires its parts and runs their worker. The parts:
// the client (servo_bus_client.h: the typed operations over the transaction client), the polls
// (servo_poller.h: servo_states, health, protect), the motion policy (motion_safety.h: what may be
// written, the servos set moving, the last words) with the stops it keeps until confirmed
// (stop_keeper.h). The bus itself keeps the queue of moves from a stream of targets
// (servo_commands). ROS-free: the ROS layer (ros/servo_bus_ros.h) converts messages to
// calls and events to messages.
//
// Threading model:
//  - The worker writes the queued moves first, then polls the servo whose poll falls due first.
//    Both take the bus after any waiting caller (the poll as background work), so a service call
//    waits for one transaction at most. The worker is one of two threads:
//      - runOn(link) (the driver): the link's reader thread. The link asks nextWork() before each
//        read and calls work() when it is due; a transaction then writes its request and reads
//        its answer on that same thread (SerialLink::pump), as a blocking client would, with no
//        second thread to wake per transaction. Other threads wake it through the link.
//      - otherwise (tests with a fake writer): a thread of its own started by start(), waiting on
//        the LoopClock (the steady clock unless a test passes its own) until the next poll or a
//        new move.
//  - queueMoves() may be called from any thread: it only stores the targets and wakes the worker.
//  - The operations of client() (the services) run on their caller's thread, serialized with the
//    worker by the client's bus lock.
//  - The ServoBusEvents hooks run on the worker thread without mutex_ held.
//  - One mutex_ guards the bus's state and its parts' (they are given it), so a decision across
//    them is one step: the e-stop drops the queue and arms the stops of the servos it finds
//    commanded under one lock, as a queued move put back checks the e-stop and the stops.
//  - With health_rate > 0 the worker also polls each servo's health (five READ_DATA, each as
//    background work, so a caller still waits for one transaction at most) when it falls due.
//  - The motion operations (move, rotate, spin, damping, relax, hold) run on their caller's thread
//    like the client's. Every motion frame, whoever writes it, passes the bus's MotionGate when it
//    is written: the e-stop (setMotionLocked) and shutdown() take the gate's lock, so no motion
//    frame goes out after they return, however long it waited for the bus.
//  - Stops (the e-stop's, stopServo()'s) are the worker's first work: setMotionLocked() and
//    stopServo() only note them, ask the bus for urgent work and wake the worker, so their caller
//    never waits for the wire. The worker writes them as urgent work (after the one transaction
//    attempt in flight, before every waiting call, scan id or poll), then reads the servo's angle
//    twice, a moment apart, until it is seen at rest; a stop that could not be written, was not
//    answered after, or left the servo moving is written again. After a reconnect (onLinkUp, on
//    the reader thread before any write can succeed) every stop of the e-stop is written again
//    first. Without a running worker (before start()) setMotionLocked() writes them itself.
//  - shutdown() closes the gate, stops the worker (joins its thread, or waits for the piece of
//    work the reader thread is doing), then says the last words (on_shutdown) on its caller's,
//    each stop confirmed like the e-stop's for at most kShutdownStopBudget.
//  - Stats are one struct under mutex_ (with the poller's counts); stats() returns a snapshot.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/loop_clock.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/motion_safety.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_config.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_events.h"
#include "serial_robot_driver/devices/servo_bus/servo_poller.h"
#include "serial_robot_driver/devices/servo_bus/stop_keeper.h"

namespace serial_robot_driver::devices::servo_bus {

class ServoBus : public core::LinkListener, public core::LinkWorker {
 public:
  // The parts' constants, by the bus's name (see servo_poller.h, stop_keeper.h, motion_safety.h).
  static constexpr std::chrono::milliseconds kFirstBackoff{ServoPoller::kFirstBackoff};
  static constexpr std::chrono::milliseconds kMaxBackoff{ServoPoller::kMaxBackoff};
  static constexpr std::chrono::milliseconds kStopSettle{StopKeeper::kStopSettle};
  static constexpr double kRestToleranceDeg = StopKeeper::kRestToleranceDeg;
  static constexpr std::chrono::milliseconds kShutdownStopBudget{MotionSafety::kShutdownStopBudget};

  /// `clock` empty: the steady clock.
  ServoBus(ServoBusConfig config, core::FrameWriter writer, ServoBusEvents events = {},
           std::shared_ptr<core::LoopClock> clock = {});
  ~ServoBus() override;
  ServoBus(const ServoBus&) = delete;
  ServoBus& operator=(const ServoBus&) = delete;

  /// The operations on the wire (the services call them directly).
  ServoBusClient& client() { return client_; }

  /// Queues moves for the worker. The latest target of a servo replaces a queued one, so the
  /// queue stays bounded (one entry per servo) while a long call holds the bus. Each is stamped
  /// with the motion gate's generation here: an e-stop engaged before its write drops it.
  void queueMoves(const std::vector<MoveRequest>& moves);
  /// Drops a move of servo `id` still waiting in the queue (another command took the servo over).
  void dropQueuedMoves(uint8_t id);
  /// Stops servo `id` where it is (a SPIN stop, no position commanded) and drops its queued moves,
  /// without waiting: the worker writes the stop ahead of queued moves, polls and waiting calls
  /// and confirms it like the e-stop's. A later motion of the servo supersedes it. Allowed while
  /// the e-stop holds. Any thread.
  void stopServo(uint8_t id);

  // Motion through the device: the client's operations, refused (kMotionRefused) while
  // setMotionLocked(true) holds, and noted so the device knows which servos it set moving
  // (stopMotion(), the shutdown). Any thread.
  ServoStatus move(const MoveRequest& request);
  ServoStatus rotate(const RotateRequest& request);
  ServoStatus spin(const SpinRequest& request);
  ServoStatus damping(uint8_t id, uint16_t power_mw, bool wait);
  /// DAMPING at config().relax_power_mw for each of `ids` (empty: every polled servo): the
  /// servos can be turned by hand. Stops at the first failure.
  ServoStatus relax(const std::vector<uint8_t>& ids);
  /// Each of `ids` (empty: every polled servo) holds the angle it is at now: READ_ANGLE, then a
  /// ROTATE there. Stops at the first failure.
  ServoStatus hold(const std::vector<uint8_t>& ids);
  /// The client's WRITE_DATA and RESET_USER_DATA, refused while they would change how or where a
  /// moving servo moves, or while the e-stop holds; an address change takes the servo's stop
  /// bookkeeping to its new id (see motion_safety.h).
  ServoStatus writeParam(uint8_t id, std::string_view param, int64_t value);
  ServoStatus resetUserData(uint8_t id);

  /// The e-stop: true locks the motion gate (no motion frame is written from its return on),
  /// drops the queued moves, refuses motion (queueMoves() included) and has every servo set
  /// moving or positioned since start-up (commandedIds()) stopped until each is seen at rest,
  /// and its stop written again every StopKeeper::kStopRepeat for as long as it holds; false
  /// lets new motion through again (nothing accepted before it moves) and keeps the stops never
  /// written. Never waits for the bus (see the threading model).
  void setMotionLocked(bool locked);
  bool motionLocked() const;
  /// Servos set spinning or moving and not stopped or relaxed since (the broadcast id 255 too).
  std::vector<uint8_t> movingIds() const;
  /// Why the bus servos may be moving the robot: the servos set moving (movingIds()), "" when
  /// none is. Any thread, cheap.
  std::string motionInForce() const;
  /// Servos set moving or positioned since start-up and not relaxed since: what the e-stop and
  /// the shutdown stop.
  std::vector<uint8_t> commandedIds() const;
  /// Stops not yet known to have reached their servo (for diagnostics).
  std::vector<PendingStopReport> pendingStops() const;
  /// Motion frames refused when their turn on the bus came (e-stop engaged or shutting down).
  uint64_t motionRefusedAtWrite() const { return safety_.refusedAtWrite(); }
  /// One report per polled servo (empty when health_rate is 0).
  std::vector<ServoHealthReport> health() const;
  /// One report per polled servo: its identity once read (empty when config().read_identity is
  /// off).
  std::vector<ServoIdentityReport> identities() const;

  /// Before start(): the worker runs on `link`'s reader thread (see the threading model), which
  /// the bus listens to. `link` must use the steady clock's time (no LoopClock of a test) and be
  /// stopped before the bus is destroyed.
  void runOn(core::SerialLink& link);
  /// Starts the worker (its thread, or the work on the link's reader thread). Idempotent.
  void start();
  /// Stops and joins the worker, gives the servos set moving what config().on_shutdown says
  /// (while the port is still open; after a service call in progress), then fails every later
  /// call (kShutdown). Idempotent.
  void shutdown();

  ServoBusWorkerStats stats() const;
  /// The configuration it was built with; settings() is the one in force.
  const ServoBusConfig& config() const { return config_; }
  /// The configuration in force: config() with what retune() changed since.
  ServoBusConfig settings() const;
  /// Takes over the tunable part of `next` whole (its ServoBusTuning and its client's
  /// ServoClientTuning): the client's timeout and retries from the next bus transaction on, the
  /// poll and health rates from the next poll on (a faster rate does not wait out the slower
  /// period still pending; health_rate 0 stops the health poll), the rest from its next use.
  /// Never waits for the bus. Expects validated values (poll_rate > 0).
  void retune(const ServoBusConfig& next);

  // LinkListener (reader thread): handed on to the client; a reconnect re-arms the stops.
  void onLinkUp() override;
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               core::Clock::time_point arrival) override;
  // LinkWorker (reader thread, after runOn()).
  core::Clock::time_point nextWork() override;
  void work() override;

 private:
  void workerLoop();
  /// When the worker has something to do next (mutex_ held): min() for a queued move, max()
  /// before start(), after shutdown() or with nothing scheduled.
  core::Clock::time_point nextWorkLocked() const;
  /// One piece of the work due, if any (mutex_ held by `lock`; released around the bus).
  void workOnce(std::unique_lock<std::mutex>& lock);
  /// A change the worker must see: its own thread, or the link's reader thread.
  void wakeWorker();
  /// Asks the client for urgent work and wakes the worker, or, without a running worker, writes
  /// the stops itself.
  void deliverStops();
  /// A queued move with the gate's generation it was accepted under.
  struct QueuedMove {
    MoveRequest move;
    core::MotionGate::Generation accepted = 0;
  };

  void dropQueuedMovesLocked(uint8_t id);  // mutex_ held
  void sendMove(const QueuedMove& queued);

  const ServoBusConfig config_;
  ServoBusConfig settings_;  // guarded by mutex_: config_ as retune() left it
  const ServoBusEvents events_;
  const std::shared_ptr<core::LoopClock> clock_;
  ServoBusClient client_;

  mutable std::mutex mutex_;  // guards everything below, the parts' state included
  std::condition_variable wake_;
  bool stop_ = false;
  bool started_ = false;
  bool working_ = false;              // work() in progress on the link's reader thread
  core::SerialLink* link_ = nullptr;  // runOn(): the worker is the link's reader thread
  std::deque<QueuedMove> queued_moves_;
  ServoPoller poller_;   // the angle and health polls
  StopKeeper stops_;     // stops not yet known to have reached their servo
  MotionSafety safety_;  // what may move; the servos set moving; the last words
  ServoBusWorkerStats stats_;
  std::thread worker_;
};

}  // namespace serial_robot_driver::devices::servo_bus
