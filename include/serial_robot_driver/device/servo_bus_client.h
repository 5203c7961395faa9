// A client for the UART bus servos (docs/protocols.md, section 3): the transactions on the wire
// and the operations built on them. ROS-free; device::ServoBus (servo_bus.h) owns one, with the
// queue and the poll, and the ROS services (ros/servo_bus_interface.h) call its operations.
//
// Threading model:
//  - Any thread may call the operations. The bus is half duplex, so they are serialized by one bus
//    mutex: a caller writes its request and waits (condition variable) for the answer, up to
//    `timeout`, re-sending up to `retries` times. Nobody else writes to the bus meanwhile.
//  - The answer arrives on the link's reader thread through onFrame(), which only matches it
//    against the pending transaction, stores it and wakes the caller: the reader never waits.
//  - The FrameWriter is called with bus_mutex_ held (that is what keeps the bus half duplex) but
//    never state_mutex_, the only lock onFrame() takes: a fake in a test may answer synchronously
//    by calling onFrame() from inside it.
//  - Stats are kept in one struct under state_mutex_; stats() returns a snapshot.
//  - Background work (readAngle with BusPriority::kBackground: the servo_states poll) takes the
//    bus only when no foreground caller waits for it, so a service call waits at most for the one
//    transaction in progress.
//  - With a ReaderPump (setReaderPump: device::ServoBus running on its link's reader thread), a
//    wait on the link's reader thread never sleeps on another thread: waiting for an answer or for
//    the bus, that thread reads the port itself (SerialLink::pump), so the answer it waits for,
//    and a foreground caller's, still arrive. Callers on other threads wait as described above.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "serial_robot_driver/device/motion_gate.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/protocol/servo_bus_codec.h"
#include "serial_robot_driver/protocol/servo_params.h"

namespace serial_robot_driver::device {

/// Why a servo operation failed. Every error before kTimeout is a rejection: nothing was written.
enum class ServoError {
  kOk = 0,
  kInvalidArgument,   ///< broadcast id where an answer is needed, angle or spin mode out of range
  kUnknownParam,      ///< no parameter of that name or data_id
  kReadOnly,          ///< write to a read-only parameter
  kOutOfRange,        ///< write value outside the parameter's range
  kDangerous,         ///< servo_id / baudrate / reset_user_data without allow_dangerous_writes
  kNotConnected,      ///< the port is down (or was lost while waiting)
  kIdInUse,           ///< servo_id change refused: a servo already answers at the new id
  kMotionRefused,     ///< a motion command while the e-stop holds or the servo is protected
  kTimeout,           ///< no answer in any attempt
  kBadAnswer,         ///< an answer with the right CMD and id whose content does not fit
  kRefused,           ///< the servo answered with result 0
  kReadBackMismatch,  ///< the value read back after a write differs from the one written
  kShutdown,          ///< the client is shutting down
  kPreempted,         ///< gave way to a stop: a poll that did not run, a motion wait cut short
};
const char* toString(ServoError error);

/// The outcome of an operation: a typed error plus one sentence for the user.
struct ServoStatus {
  ServoError error = ServoError::kOk;
  std::string message;
  bool ok() const { return error == ServoError::kOk; }
};

struct ServoBusOptions {
  std::chrono::milliseconds timeout{50};  ///< wait for one answer
  int retries = 1;                        ///< re-sends after a timeout (attempts = retries + 1)
  bool allow_dangerous_writes = false;    ///< arms servo_id, baudrate and reset_user_data
};

/// A parameter value in the unit of the parameter table (mV, mA, mW, degC, ms, 0.1deg or raw "").
struct ServoParamValue {
  std::string name;
  uint8_t data_id = 0;
  int64_t value = 0;
  std::string unit;
};

struct RotateRequest {
  uint8_t id = 0;
  double angle_deg = 0.0;  ///< sent as int16 in 0.1 deg: -3276.8 .. 3276.7
  uint16_t interval_ms = 0;
  uint16_t power_mw = 0;   ///< 0: the servo's default
  /// Wait for the completion answer (sent only when response_switch = 1) up to
  /// interval_ms + timeout; never re-sent.
  bool wait = false;
};

struct SpinRequest {
  uint8_t id = 0;
  bool clockwise = false;
  uint8_t mode = 0;        ///< 0 stop, 1 continuous, 2 `value` turns, 3 `value` ms
  uint16_t speed_dps = 0;
  uint16_t value = 0;
  /// Wait for the completion answer (response_switch = 1) up to the expected duration (mode 2:
  /// value * 360 / speed_dps s, mode 3: value ms, else 0) + timeout; never re-sent.
  bool wait = false;
};

/// One request for the whole motion set of CMD 8 and 11..15 (servo/move). The command follows from
/// the fields: velocity_dps > 0 -> by velocity (12, multi-turn 15); else accel_ms or decel_ms > 0
/// -> by interval with ramps (11 / 14); else plain (8 / 13).
struct MoveRequest {
  uint8_t id = 0;
  double angle_deg = 0.0;  ///< single-turn within +-180, multi-turn within +-368640
  bool multi_turn = false;
  uint32_t interval_ms = 0;   ///< single-turn at most 65535, multi-turn at most 4096000
  double velocity_dps = 0.0;  ///< 0: not by velocity; else 0.1 .. 750
  uint16_t accel_ms = 0;      ///< 0: not given (20, the firmware's shortest, is sent where needed)
  uint16_t decel_ms = 0;
  uint16_t power_mw = 0;  ///< 0: the servo's default limit
};

/// A multi-turn angle (CMD 16).
struct MultiTurnReading {
  double angle_deg = 0.0;
  int16_t turns = 0;
};

struct ServoBusStats {
  uint64_t transactions = 0;   ///< requests that expected an answer (once, however many attempts)
  uint64_t commands = 0;       ///< motion frames written without waiting for an answer
  uint64_t timeouts = 0;       ///< transactions that got no answer in any attempt
  uint64_t retries = 0;        ///< requests re-sent after a timeout or a malformed answer
  uint64_t mismatched = 0;     ///< answers matching no pending transaction (other CMD/id, late)
  uint64_t garbled = 0;        ///< right CMD and id, but a content that does not fit
  uint64_t echoes = 0;         ///< our own requests read back (half-duplex echo), skipped
  double last_latency_ms = 0.0;  ///< request written -> answer's last byte read
  double max_latency_ms = 0.0;
};

/// Who waits for the bus: a caller (a service) goes before background work (the poll). kWorker
/// is the bus's own worker, which writes the stops: it waits like a caller, but gives way to urgent
/// work (kPreempted) instead of waiting for it, before the bus is taken and between attempts.
enum class BusPriority { kCaller, kWorker, kBackground };

/// How the link's reader thread waits without sleeping on another thread: it reads its port
/// (SerialLink::pump) and is woken by wake() when what it waits for may have changed.
struct ReaderPump {
  std::function<bool()> on_reader_thread;
  /// Reads once, up to `until`; false when the port is down or stopping.
  std::function<bool(Clock::time_point until)> pump;
  std::function<void()> wake;
};

/// The bus lock, by priority: urgent work (a stop) goes first and waits only for the holder;
/// foreground callers (lock()) go next; background ones (lockBackground()) take the bus only while
/// nobody else waits for it. Usable with std::lock_guard (lock()/unlock()).
class BusMutex {
 public:
  void lock();
  void unlock();
  /// False, without the bus, when urgent work is asked while it waits (the poll gives way).
  bool lockBackground();
  /// A caller that gives way: false, without the bus, when urgent work is asked while it waits.
  bool lockUnlessUrgent();
  /// A stop: waits for the holder only (one transaction attempt at most), never for a queue.
  void lockUrgent();
  /// Urgent work is coming: from now until endUrgent(), lock() and lockBackground() wait (a
  /// background wait gives up) and a holder between two attempts hands the bus over.
  void requestUrgent();
  void endUrgent();
  bool urgentRequested();
  /// Between two attempts of one transaction: hands the bus to urgent work asked meanwhile and
  /// takes it back before any other caller.
  void yieldToUrgent();
  /// Foreground callers waiting right now (for tests and diagnostics).
  int foregroundWaiting();
  /// Set before any use: the reader thread pumps its port while it waits for the bus.
  void setReaderPump(const ReaderPump* pump) { pump_ = pump; }

 private:
  /// Waits (mutex_ held by `lock`) until `free` holds: on a condition variable, or pumping.
  template <typename Predicate>
  void waitTurn(std::unique_lock<std::mutex>& lock, Predicate free);
  void wakeWaiters(std::unique_lock<std::mutex>& lock);

  std::mutex mutex_;
  std::condition_variable released_;
  bool held_ = false;
  int waiting_ = 0;               ///< foreground callers waiting for the bus
  bool urgent_ = false;           ///< requestUrgent() .. endUrgent()
  int yielded_ = 0;               ///< holders that handed the bus to urgent work
  bool reader_waiting_ = false;   ///< the pumping reader thread waits: unlock() wakes it
  const ReaderPump* pump_ = nullptr;
};

/// Whether a motion frame waits for the motion gate (see motion_gate.h) or is a safety action
/// (a stop, a relax at shutdown or for temperature) that is always let through.
enum class FrameGate { kMotion, kSafetyAction };

class ServoBusClient : public LinkListener {
 public:
  /// The longest motion a caller may wait for (the longest ROTATE interval).
  static constexpr std::chrono::milliseconds kMaxMotionWait{65535};

  ServoBusClient(ServoBusOptions options, FrameWriter writer);

  /// PING: ok when the servo answered.
  ServoStatus ping(uint8_t id);
  /// READ_DATA of a parameter given by name or data_id as text ("51").
  /// kBackground (the health poll): the bus is taken only while no other caller waits for it.
  ServoStatus readParam(uint8_t id, std::string_view param, ServoParamValue* value,
                        BusPriority priority = BusPriority::kCaller);
  /// WRITE_DATA after checkWrite, then a read-back to confirm. A servo_id change first pings the
  /// new id and is refused if a servo answers there; a baudrate write is not read back (it takes
  /// effect at once).
  ServoStatus writeParam(uint8_t id, std::string_view param, int64_t value);
  /// READ_ANGLE in degrees. `arrival` (optional): when the answer's last byte was read.
  /// kBackground (the servo_states poll): one attempt, and the bus is taken only while no other
  /// caller waits for it.
  ServoStatus readAngle(uint8_t id, double* angle_deg, Clock::time_point* arrival = nullptr,
                        BusPriority priority = BusPriority::kCaller);
  /// CMD 16: the multi-turn angle and the turn count.
  ServoStatus readMultiTurnAngle(uint8_t id, MultiTurnReading* reading);
  /// CMD 8 or 11..15, chosen by the request (see MoveRequest); returns once the frame is written.
  ServoStatus move(const MoveRequest& request, BusPriority priority = BusPriority::kCaller);
  /// PINGs first_id..last_id, one attempt each (a silent id costs one timeout), and lists the ids
  /// that answered. The bus is taken per id, so other callers are served in between.
  ServoStatus scan(uint8_t first_id, uint8_t last_id, std::vector<uint8_t>* ids);
  /// ROTATE / SPIN / DAMPING return once the frame is written unless `wait` is set. Id 255
  /// (broadcast) is accepted only without wait.
  /// Each motion frame is written through the motion gate (setMotionGate), decided when its turn
  /// on the bus comes: refused then (kMotionRefused), nothing is written. A SPIN stop, and a
  /// DAMPING with FrameGate::kSafetyAction, always pass.
  ServoStatus rotate(const RotateRequest& request);
  ServoStatus spin(const SpinRequest& request);
  ServoStatus damping(uint8_t id, uint16_t power_mw, bool wait,
                      FrameGate gate = FrameGate::kMotion);
  /// SPIN stops to `ids` as urgent work (BusMutex::lockUrgent): written after the one transaction
  /// attempt in flight, before every waiting caller. `written[i]`: whether the stop of ids[i]
  /// went out. Fire and forget: whether the servo heard it is for the caller to find out.
  void writeStops(const std::vector<uint8_t>& ids, std::vector<bool>* written);
  /// Urgent work is coming (see BusMutex::requestUrgent); a caller waiting for a motion's
  /// completion stops waiting (kPreempted: the motion went out, its end was not awaited).
  void requestUrgent();
  void endUrgent();
  /// READ_BATCH_DATA: the 22 user-block parameters (data_id 32..53) in table order.
  ServoStatus readAll(uint8_t id, std::vector<ServoParamValue>* values);
  /// RESET_USER_DATA (dangerous: refused unless allow_dangerous_writes). The reset also sets the
  /// servo's id to its default 0, so the answer may come from id 0 or not at all: without an
  /// answer the client PINGs id 0, and a servo there means the reset worked.
  ServoStatus resetUserData(uint8_t id);

  /// Wakes a waiting caller and fails every later call with kShutdown. Idempotent.
  void shutdown();

  ServoBusStats stats() const;
  /// The options in force (a copy: retune() may change timeout and retries meanwhile).
  ServoBusOptions options() const;
  /// A new timeout and retry count for the transactions that start from now on; one that runs
  /// keeps what it started with. Never waits for the bus.
  void retune(std::chrono::milliseconds timeout, int retries);
  /// Callers (not background work) waiting for the bus right now (for tests and diagnostics).
  int callersWaiting() { return bus_mutex_.foregroundWaiting(); }
  /// Before any call: waits on the pump's reader thread read the port (see the threading model).
  void setReaderPump(ReaderPump pump);
  /// Before any call: the gate every motion frame passes when it is written (nullptr: none), and
  /// what is told, under the gate's lock, of each motion frame that went out (the servo's id).
  void setMotionGate(MotionGate* gate, std::function<void(uint8_t id)> on_motion_written = {}) {
    gate_ = gate;
    on_motion_written_ = std::move(on_motion_written);
  }

  // LinkListener (reader thread).
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point arrival) override;

 private:
  /// What an answer must look like to complete the pending transaction.
  struct Expectation {
    Expectation() = default;
    /// The answer of `answer_cmd` as the command table sizes it (commands of a fixed answer).
    Expectation(protocol::servo::Command answer_cmd, uint8_t answer_id);
    Expectation(protocol::servo::Command answer_cmd, uint8_t answer_id, std::size_t size)
        : cmd(answer_cmd), id(answer_id), content_size(size) {}

    protocol::servo::Command cmd = protocol::servo::Command::kPing;
    uint8_t id = 0;
    std::optional<uint8_t> alt_id;   ///< also accepted (a servo_id change may answer at the new id)
    std::optional<uint8_t> data_id;  ///< READ_DATA / WRITE_DATA: content[1]
    std::size_t content_size = 0;
  };
  struct Pending {
    bool active = false;
    Expectation expect;
    bool answered = false;
    bool garbled = false;
    protocol::servo::Packet answer;
    Clock::time_point arrival;
  };

  // The helpers below expect bus_mutex_ to be held by the caller.
  /// `gate` kMotion: the request is a motion frame (a wait for its completion, which a stop may
  /// cut short); it is written through the motion gate.
  /// `give_way` (BusPriority::kWorker): urgent work asked before a re-send ends it (kPreempted).
  ServoStatus transact(const std::vector<uint8_t>& request, const Expectation& expect,
                       std::chrono::milliseconds timeout, int attempts,
                       protocol::servo::Packet* answer, FrameGate gate = FrameGate::kSafetyAction,
                       bool give_way = false);
  /// Takes the bus at `priority`; false (and nothing held) when it gave way to urgent work.
  bool takeBus(BusPriority priority);
  /// Writes one request, through the motion gate when `gate` is kMotion. nullopt when written;
  /// else why not (the gate's refusal, or the port is down).
  std::optional<ServoStatus> writeRequest(const std::vector<uint8_t>& request,
                                          protocol::servo::Command cmd, uint8_t id, FrameGate gate);
  /// transact() with the configured timeout and retries: the usual request/answer exchange.
  ServoStatus exchangeLocked(const std::vector<uint8_t>& request, const Expectation& expect,
                             protocol::servo::Packet* answer);
  /// Fire and forget: a motion command without wait.
  ServoStatus sendCommand(const std::vector<uint8_t>& request, protocol::servo::Command cmd,
                          uint8_t id, FrameGate gate);
  /// The shared tail of ROTATE/SPIN/DAMPING: send, or transact and check the result byte.
  ServoStatus sendMotion(const std::vector<uint8_t>& request, protocol::servo::Command cmd,
                         uint8_t id, bool wait, std::chrono::milliseconds motion_time,
                         FrameGate gate);
  ServoStatus readParamLocked(uint8_t id, const protocol::servo::ParamInfo& param,
                              ServoParamValue* value);
  ServoStatus pingLocked(uint8_t id);
  /// One PING attempt, no retries (scan, and the check after a silent reset).
  ServoStatus pingOnceLocked(uint8_t id);
  bool matches(const protocol::servo::Packet& packet) const;  // state_mutex_ held
  /// Waits (state_mutex_ held by `lock`) until the pending transaction is answered, garbled,
  /// lost or shut down, or `deadline` passes.
  void waitForAnswer(std::unique_lock<std::mutex>& lock, Clock::time_point deadline);
  /// exchangeLocked() of a single request, taking bus_mutex_ itself.
  ServoStatus exchange(const std::vector<uint8_t>& request, const Expectation& expect,
                       protocol::servo::Packet* answer);

  ServoBusOptions options_;  // timeout and retries guarded by state_mutex_ (retune), read via options()
  const FrameWriter writer_;
  ReaderPump pump_;  // set before any call; empty: every wait is on a condition variable
  MotionGate* gate_ = nullptr;  // set before any call
  std::function<void(uint8_t id)> on_motion_written_;

  BusMutex bus_mutex_;  // one transaction on the wire at a time

  mutable std::mutex state_mutex_;  // guards everything below; shared with the reader thread
  std::condition_variable answer_cv_;
  Pending pending_;
  std::vector<uint8_t> last_request_;  // recognises the half-duplex echo
  bool link_lost_ = false;             // the port went down while a transaction was pending
  bool stopping_ = false;
  bool urgent_ = false;       // requestUrgent() .. endUrgent(): a motion wait gives way
  bool motion_wait_ = false;  // the pending transaction waits for a motion's completion
  ServoBusStats stats_;
};

}  // namespace serial_robot_driver::device
