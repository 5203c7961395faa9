// The UART servo bus as a device: the client (the wire and its operations), the queue of moves
// from a stream of targets (servo_commands) and the scheduled angle poll (servo_states), with the
// back-off of a servo that stops answering. ROS-free: the ROS layer (ros/servo_bus_interface.h)
// converts messages to calls and events to messages.
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
//  - Stats are one struct under mutex_; stats() returns a snapshot.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/device/loop_clock.h"
#include "serial_robot_driver/device/motion_gate.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/device/servo_bus_client.h"
#include "serial_robot_driver/device/servo_health.h"

namespace serial_robot_driver::device {

/// What servos set moving get when the bus shuts down (before its port closes).
enum class ShutdownAction { kStop, kRelax, kNone };
/// "stop", "relax", "none"; nullopt for anything else.
std::optional<ShutdownAction> shutdownActionFromString(const std::string& text);
const char* toString(ShutdownAction action);

struct ServoBusConfig {
  ServoBusOptions client;
  std::vector<uint8_t> polled_ids;  ///< servos whose angle is polled (servo_states)
  double poll_rate = 10.0;          ///< polls per second of each polled servo, > 0
  uint16_t relax_power_mw = 50;     ///< DAMPING power of relax()
  /// For each servo set spinning or moving: kStop a SPIN stop, kRelax relax(), kNone nothing.
  ShutdownAction on_shutdown = ShutdownAction::kStop;
  /// Health polls (voltage, current, power, temperature, status) per second of each polled
  /// servo, as background work between the angle polls; 0: none.
  double health_rate = 1.0;
  /// A servo at its own temperature limit is relaxed and its moves refused until it has cooled
  /// OverheatGuard::kCoolDownC below it.
  bool protect = false;
};

/// The health of one polled servo (health_rate > 0).
struct ServoHealthReport {
  uint8_t id = 0;
  bool polled = false;        ///< at least one health poll finished (answered or not)
  bool online = false;        ///< the last health poll was answered
  std::string last_error;     ///< why the last poll failed
  bool limits_known = false;  ///< the servo's limits, read once when it first answered
  ServoLimits limits;
  ServoReadings readings;     ///< valid once a poll was answered
  HealthAssessment assessment;
  bool overheated = false;    ///< protect: relaxed, its moves refused
};

/// One polled angle.
struct ServoAngleSample {
  uint8_t id = 0;
  double angle_deg = 0.0;
  Clock::time_point arrival;  ///< when the answer's last byte was read
};

/// What the bus reports; every hook may be empty.
struct ServoBusEvents {
  std::function<void(const ServoAngleSample&)> on_angle;
  /// A polled servo stopped answering (once, until it answers again); asked again after `backoff`.
  std::function<void(uint8_t id, const ServoStatus& status, std::chrono::milliseconds backoff)>
      on_servo_silent;
  std::function<void(const MoveRequest& move, const ServoStatus& status)> on_move_failed;
  /// protect: servo `report.id` was relaxed for its temperature (`overheated`), or has cooled.
  std::function<void(const ServoHealthReport& report)> on_overheat;
  /// A stop of servo `id`: ok once the servo is seen at rest after it; an error when an attempt
  /// failed (it is retried) or, at shutdown, when it could not be confirmed in time.
  std::function<void(uint8_t id, const ServoStatus& status)> on_stop;
};

/// A stop not yet known to have reached its servo.
struct PendingStopReport {
  uint8_t id = 0;
  int written = 0;  ///< times the stop went out so far
  std::string why;  ///< what is still missing: written, answered, seen at rest
};

struct ServoBusWorkerStats {
  uint64_t angles_polled = 0;        ///< on_angle reports
  uint64_t moves_sent = 0;           ///< queued moves written
  uint64_t moves_failed = 0;         ///< queued moves the client refused or could not write
  uint64_t moves_replaced = 0;       ///< queued moves replaced by a newer target of the same servo
  std::vector<uint8_t> offline_ids;  ///< polled servos in back-off
  /// Angle reads per second the schedule asks for: the poll rate in force times the polled
  /// servos not in back-off. What the line delivers is angles_polled over time.
  double asked_poll_rate = 0.0;
};

class ServoBus : public LinkListener, public LinkWorker {
 public:
  /// A servo that stops answering the poll is asked again after a back-off that doubles from the
  /// first to the longest, so a dead servo costs one timeout per back-off period, not per poll.
  static constexpr std::chrono::milliseconds kFirstBackoff{500};
  static constexpr std::chrono::milliseconds kMaxBackoff{8000};
  /// A stopped servo's angle is read twice this far apart; it is at rest when it moved no more
  /// than kRestToleranceDeg meanwhile.
  static constexpr std::chrono::milliseconds kStopSettle{100};
  static constexpr double kRestToleranceDeg = 0.5;
  /// How long shutdown() keeps writing and confirming its stops, at most.
  static constexpr std::chrono::milliseconds kShutdownStopBudget{1000};

  /// `clock` empty: the steady clock.
  ServoBus(ServoBusConfig config, FrameWriter writer, ServoBusEvents events = {},
           std::shared_ptr<LoopClock> clock = {});
  ~ServoBus() override;
  ServoBus(const ServoBus&) = delete;
  ServoBus& operator=(const ServoBus&) = delete;

  /// The operations on the wire (the services call them directly).
  ServoBusClient& client() { return client_; }

  /// Queues moves for the worker. The latest target of a servo replaces a queued one, so the
  /// queue stays bounded (one entry per servo) while a long call holds the bus.
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

  /// The e-stop: true locks the motion gate (no motion frame is written from its return on),
  /// drops the queued moves, refuses motion (queueMoves() included) and has every servo set
  /// moving or positioned since start-up (commandedIds()) stopped until each is seen at rest;
  /// false lets motion through again. Never waits for the bus (see the threading model).
  void setMotionLocked(bool locked);
  bool motionLocked() const;
  /// Servos set spinning or moving and not stopped or relaxed since (the broadcast id 255 too).
  std::vector<uint8_t> movingIds() const;
  /// Servos set moving or positioned since start-up and not relaxed since: what the e-stop and
  /// the shutdown stop.
  std::vector<uint8_t> commandedIds() const;
  /// Stops not yet known to have reached their servo (for diagnostics).
  std::vector<PendingStopReport> pendingStops() const;
  /// Motion frames refused when their turn on the bus came (e-stop engaged or shutting down).
  uint64_t motionRefusedAtWrite() const { return gate_.refusedAtWrite(); }
  /// One report per polled servo (empty when health_rate is 0).
  std::vector<ServoHealthReport> health() const;

  /// Before start(): the worker runs on `link`'s reader thread (see the threading model), which
  /// the bus listens to. `link` must use the steady clock's time (no LoopClock of a test) and be
  /// stopped before the bus is destroyed.
  void runOn(SerialLink& link);
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
  /// Applies the tunable part of `next`: client.timeout and client.retries from the next bus
  /// transaction on, poll_rate and health_rate from the next poll on (a faster rate does not wait
  /// out the slower period still pending; health_rate 0 stops the health poll), relax_power_mw,
  /// protect and on_shutdown from their next use. Never waits for the bus. Expects validated
  /// values (poll_rate > 0).
  void retune(const ServoBusConfig& next);

  // LinkListener (reader thread): handed on to the client; a reconnect re-arms the stops.
  void onLinkUp() override;
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point arrival) override;
  // LinkWorker (reader thread, after runOn()).
  Clock::time_point nextWork() override;
  void work() override;

 private:
  /// One polled servo and its schedule.
  struct PolledServo {
    uint8_t id = 0;
    Clock::time_point next_poll;
    std::chrono::milliseconds backoff{0};  ///< 0: online
  };

  void workerLoop();
  /// When the worker has something to do next (mutex_ held): min() for a queued move, max()
  /// before start(), after shutdown() or with nothing scheduled.
  Clock::time_point nextWorkLocked() const;
  /// One piece of the work due, if any (mutex_ held by `lock`; released around the bus).
  void workOnce(std::unique_lock<std::mutex>& lock);
  /// A change the worker must see: its own thread, or the link's reader thread.
  void wakeWorker();
  /// A stop until the servo is seen at rest (see the threading model).
  struct PendingStop {
    enum class Phase { kWrite, kFirstLook, kSecondLook } phase = Phase::kWrite;
    Clock::time_point due;
    double first_angle = 0.0;
    int written = 0;
    bool port_down = false;  ///< the last write failed
    std::string why = "not written yet";
  };
  /// How stop work is paced: by the bus's clock (the worker), or back to back with real sleeps
  /// for the settle (shutdown(), on its caller's thread, whatever clock the bus has).
  enum class StopPace { kScheduled, kNow };

  /// A motion frame of servo `id` went out (told by the client under the motion gate's lock, so
  /// an e-stop engaged right after it finds the servo among those to stop). A pending stop of
  /// the servo (a hold) is superseded.
  void noteCommanded(uint8_t id);
  /// Notes the outcome of a motion command of servo `id`: moving or at rest.
  void noteMotion(uint8_t id, bool moving);
  ServoStatus refuseWhileLocked(uint8_t id) const;
  void dropQueuedMovesLocked(uint8_t id);  // mutex_ held
  /// Adds a stop of `id` to be written now (mutex_ held).
  void armStopLocked(uint8_t id, Clock::time_point now);
  /// Asks the client for urgent work and wakes the worker, or, without a running worker, writes
  /// the stops itself.
  void deliverStops();
  /// Reserves the bus for the stops (ServoBusClient::requestUrgent) until endUrgentLocked().
  void askUrgent();
  void endUrgentLocked();  // mutex_ held
  /// When the stop work falls due next (mutex_ held); max() when none.
  Clock::time_point nextStopWork() const;
  /// One piece of stop work that is due (mutex_ held by `lock`, released around the bus): every
  /// stop to be written, or one look at a stopped servo. False when nothing was due.
  bool stopWorkOnce(std::unique_lock<std::mutex>& lock, StopPace pace);
  void writeDueStops(std::unique_lock<std::mutex>& lock, StopPace pace);
  void lookAtStoppedServo(std::unique_lock<std::mutex>& lock, uint8_t id, StopPace pace);
  void finalWords();
  /// The health poll's schedule: the servo due first, and when (max when none).
  Clock::time_point nextHealthPoll() const;  // mutex_ held
  void pollHealthOnce(std::size_t index);
  /// Reads `names` in order into `values`; the first failure.
  ServoStatus readHealthParams(uint8_t id, const std::vector<const char*>& names,
                               std::vector<int64_t>* values);
  void sendMove(const MoveRequest& move);
  void pollOnce(PolledServo& servo);

  const ServoBusConfig config_;
  ServoBusConfig settings_;  // guarded by mutex_: config_ as retune() left it
  const ServoBusEvents events_;
  const std::shared_ptr<LoopClock> clock_;
  Clock::duration poll_period_;  // guarded by mutex_ (retune)
  ServoBusClient client_;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  bool stop_ = false;
  bool started_ = false;
  bool working_ = false;          // work() in progress on the link's reader thread
  SerialLink* link_ = nullptr;    // runOn(): the worker is the link's reader thread
  std::deque<MoveRequest> queued_moves_;
  std::map<uint8_t, PendingStop> stops_;  // not yet known to have reached their servo
  std::set<uint8_t> commanded_;           // set moving or positioned since start-up
  bool urgent_asked_ = false;             // askUrgent() .. endUrgentLocked()
  MotionGate gate_;                       // every motion frame passes it when written
  std::vector<PolledServo> polled_;  // schedule changed by the worker (and by retune)
  std::set<uint8_t> moving_;          // servos set moving and not stopped since
  bool motion_locked_ = false;
  bool final_words_said_ = false;
  // Health polls: one entry per polled servo, changed by the worker only (read under mutex_).
  struct HealthServo {
    ServoHealthReport report;
    Clock::time_point next_poll;
    OverheatGuard guard;
  };
  std::vector<HealthServo> health_;  // one per polled servo; polled while health_period_ > 0
  Clock::duration health_period_{0};
  ServoBusWorkerStats stats_;
  std::thread worker_;
};

}  // namespace serial_robot_driver::device
