// The transaction client of the UART bus servos (docs/protocols.md, section 3): one request on the
// wire, its answer matched, timed out and retried, the half-duplex echo skipped, one transaction
// at a time under the bus lock (bus_mutex.h). It knows no command beyond the answer it expects:
// ServoBusClient (servo_bus_client.h) builds the typed operations on it. ROS-free.
//
// Threading model:
//  - Any thread may run a transaction. The bus is half duplex, so they are serialized by one bus
//    mutex: a caller writes its request and waits (condition variable) for the answer, up to
//    `timeout`, re-sending up to `retries` times. Nobody else writes to the bus meanwhile.
//  - The answer arrives on the link's reader thread through onFrame(), which only matches it
//    against the pending transaction, stores it and wakes the caller: the reader never waits.
//  - The FrameWriter is called with bus_mutex_ held (that is what keeps the bus half duplex) but
//    never state_mutex_, the only lock onFrame() takes: a fake in a test may answer synchronously
//    by calling onFrame() from inside it.
//  - Stats are kept in one struct under state_mutex_; stats() returns a snapshot.
//  - Background work (BusPriority::kBackground: the servo_states and health polls) takes the
//    bus only when no foreground caller waits for it, so a service call waits at most for the one
//    transaction in progress.
//  - Urgent work (the worker's stops, writeStops; a stop service's call, BusPriority::kStop) waits
//    for the one transaction attempt in flight, never longer: a holder that keeps the bus for
//    several transactions (a write, its read-back; a reset, the PING after it) hands it over
//    before each attempt (transact() calls BusMutex::yieldToUrgent), and a caller waiting for a
//    motion's completion stops waiting (kPreempted) while urgent work is asked or waits, or while
//    a stop call waits to be served (setStopCallsQueued: the ROS layer's stop queue).
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
#include <utility>
#include <vector>

#include "serial_robot_driver/core/motion_gate.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/bus_mutex.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"

namespace serial_robot_driver::devices::servo_bus {

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
/// Whether `error` refuses the request for what it asks (counted as a refused input), not for
/// what the bus or the servo did.
bool refusesRequest(ServoError error);

/// The outcome of an operation: a typed error plus one sentence for the user.
struct ServoStatus {
  ServoError error = ServoError::kOk;
  std::string message;
  bool ok() const { return error == ServoError::kOk; }
};

/// The options that can change while the bus runs (retune() takes them over whole).
struct ServoClientTuning {
  std::chrono::milliseconds timeout{50};  ///< wait for one answer
  int retries = 1;                        ///< re-sends after a timeout (attempts = retries + 1)
};

struct ServoBusOptions : ServoClientTuning {
  bool allow_dangerous_writes = false;  ///< arms servo_id, baudrate and reset_user_data
};

struct ServoBusStats {
  uint64_t transactions = 0;     ///< requests that expected an answer (once, however many attempts)
  uint64_t commands = 0;         ///< motion frames written without waiting for an answer
  uint64_t timeouts = 0;         ///< transactions that got no answer in any attempt
  uint64_t retries = 0;          ///< requests re-sent after a timeout or a malformed answer
  uint64_t mismatched = 0;       ///< answers matching no pending transaction (other CMD/id, late)
  uint64_t garbled = 0;          ///< right CMD and id, but a content that does not fit
  uint64_t echoes = 0;           ///< our own requests read back (half-duplex echo), skipped
  double last_latency_ms = 0.0;  ///< request written -> answer's last byte read
  double max_latency_ms = 0.0;
};

/// Whether a motion frame waits for the motion gate (see motion_gate.h) or is a safety action
/// (a stop, a relax at shutdown or for temperature) that is always let through.
enum class FrameGate { kMotion, kSafetyAction };

class ServoTransactions : public core::LinkListener {
 public:
  /// What an answer must look like to complete the pending transaction.
  struct Expectation {
    Expectation() = default;
    /// The answer of `answer_cmd` as the command table sizes it (commands of a fixed answer).
    Expectation(Command answer_cmd, uint8_t answer_id);
    Expectation(Command answer_cmd, uint8_t answer_id, std::size_t size)
        : cmd(answer_cmd), id(answer_id), content_size(size) {}

    Command cmd = Command::kPing;
    uint8_t id = 0;
    std::optional<uint8_t> alt_id;   ///< also accepted (a servo_id change may answer at the new id)
    std::optional<uint8_t> data_id;  ///< READ_DATA / WRITE_DATA: content[1]
    std::size_t content_size = 0;
  };

  ServoTransactions(ServoBusOptions options, core::FrameWriter writer);

  // Taking the bus: every helper below expects it held by the caller (std::lock_guard on
  // busMutex(), or takeBus() adopted).
  BusMutex& busMutex() { return bus_mutex_; }
  /// Takes the bus at `priority`; false (and nothing held) when it gave way to urgent work
  /// (kWorker, kBackground only).
  bool takeBus(BusPriority priority);

  /// `gate` kMotion: the request is a motion frame (a wait for its completion, which a stop may
  /// cut short); it is written through the motion gate.
  /// Before each attempt the bus is handed to urgent work asked or waiting meanwhile (see
  /// BusMutex::yieldToUrgent). `give_way` (BusPriority::kWorker): the worker's stops asked before
  /// an attempt end it instead (kPreempted).
  /// `arrival` (optional): when the answer's last byte was read.
  /// `accepted` (a motion): the gate's generation it was accepted under (MotionGate::writeIfOpen).
  ServoStatus transact(const std::vector<uint8_t>& request, const Expectation& expect,
                       std::chrono::milliseconds timeout, int attempts, Packet* answer,
                       FrameGate gate = FrameGate::kSafetyAction, bool give_way = false,
                       core::Clock::time_point* arrival = nullptr,
                       std::optional<core::MotionGate::Generation> accepted = std::nullopt);
  /// transact() with the configured timeout and retries: the usual request/answer exchange.
  ServoStatus exchangeLocked(const std::vector<uint8_t>& request, const Expectation& expect,
                             Packet* answer);
  /// exchangeLocked() of a single request, taking the bus itself.
  ServoStatus exchange(const std::vector<uint8_t>& request, const Expectation& expect,
                       Packet* answer);
  /// Fire and forget: a motion command without wait.
  ServoStatus sendCommand(const std::vector<uint8_t>& request, Command cmd, uint8_t id,
                          FrameGate gate,
                          std::optional<core::MotionGate::Generation> accepted = std::nullopt);

  /// SPIN stops to `ids` as urgent work (BusMutex::lockUrgent): written after the one transaction
  /// attempt in flight, before every waiting caller. `written[i]`: whether the stop of ids[i]
  /// went out. Takes the bus itself.
  void writeStops(const std::vector<uint8_t>& ids, std::vector<bool>* written);
  /// Urgent work is coming (see BusMutex::requestUrgent); a caller waiting for a motion's
  /// completion stops waiting (kPreempted: the motion went out, its end was not awaited).
  void requestUrgent();
  void endUrgent();
  /// Before any call: whether a stop call waits to be served (`queued`, any thread): while it
  /// does, a motion wait gives way (kPreempted), so the thread that serves stops is free for it.
  /// stopCallQueued() tells a wait in progress to look again.
  void setStopCallsQueued(std::function<bool()> queued) { stop_calls_queued_ = std::move(queued); }
  void stopCallQueued();

  /// Wakes a waiting caller and fails every later transaction with kShutdown. Idempotent.
  void shutdown();
  ServoBusStats stats() const;
  /// The options in force (a copy: retune() may change timeout and retries meanwhile).
  ServoBusOptions options() const;
  /// A new timeout and retry count for the transactions that start from now on; one that runs
  /// keeps what it started with. Never waits for the bus.
  void retune(const ServoClientTuning& next);
  /// Before any transaction: waits on the pump's reader thread read the port.
  void setReaderPump(ReaderPump pump);
  /// Before any transaction: the gate every motion frame passes when it is written (nullptr:
  /// none), and what is told, under the gate's lock, of each motion frame that went out.
  void setMotionGate(core::MotionGate* gate, std::function<void(uint8_t id)> on_motion_written) {
    gate_ = gate;
    on_motion_written_ = std::move(on_motion_written);
  }

  // LinkListener (reader thread).
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               core::Clock::time_point arrival) override;

 private:
  struct Pending {
    bool active = false;
    Expectation expect;
    bool answered = false;
    bool garbled = false;
    Packet answer;
    core::Clock::time_point arrival;
  };

  /// Writes one request, through the motion gate when `gate` is kMotion (voided when an e-stop
  /// engaged since generation `accepted`). nullopt when written; else why not (the gate's
  /// refusal, or the port is down).
  std::optional<ServoStatus> writeRequest(const std::vector<uint8_t>& request, Command cmd,
                                          uint8_t id, FrameGate gate,
                                          std::optional<core::MotionGate::Generation> accepted);
  bool matches(const Packet& packet) const;  // state_mutex_ held
  /// Sets up the pending transaction of one attempt; false when shutting down.
  bool beginAttempt(const std::vector<uint8_t>& request, const Expectation& expect, FrameGate gate);
  /// The pending transaction's answer, its latency counted (state_mutex_ held).
  ServoStatus answeredLocked(core::Clock::time_point sent_at, Packet* answer);
  /// kBadAnswer: only malformed answers (the last one `garbled_size` content bytes).
  static ServoStatus malformed(const Expectation& expect, std::size_t garbled_size);
  /// kTimeout after `attempts` unanswered attempts, counted.
  ServoStatus timedOut(const Expectation& expect, std::chrono::milliseconds timeout, int attempts);
  /// Whether a motion wait in progress gives way to a stop (state_mutex_ held).
  bool motionWaitCutLocked() const;
  /// BusMutex::lockUrgent, a motion wait cut short meanwhile.
  void lockUrgent();
  /// Waits (state_mutex_ held by `lock`) until the pending transaction is answered, garbled,
  /// lost or shut down, or `deadline` passes.
  void waitForAnswer(std::unique_lock<std::mutex>& lock, core::Clock::time_point deadline);

  ServoBusOptions
      options_;  // timeout and retries guarded by state_mutex_ (retune), read via options()
  const core::FrameWriter writer_;
  ReaderPump pump_;  // set before any call; empty: every wait is on a condition variable
  core::MotionGate* gate_ = nullptr;  // set before any call
  std::function<void(uint8_t id)> on_motion_written_;
  std::function<bool()> stop_calls_queued_;  // set before any call; empty: none

  BusMutex bus_mutex_;  // one transaction on the wire at a time

  mutable std::mutex state_mutex_;  // guards everything below; shared with the reader thread
  std::condition_variable answer_cv_;
  Pending pending_;
  std::vector<uint8_t> last_request_;  // recognises the half-duplex echo
  bool link_lost_ = false;             // the port went down while a transaction was pending
  bool stopping_ = false;
  bool urgent_ = false;       // requestUrgent() .. endUrgent(): a motion wait gives way
  bool motion_wait_ = false;  // the pending transaction waits for a motion's completion
  int stops_waiting_ = 0;     // lockUrgent() calls waiting for the bus
  ServoBusStats stats_;
};

}  // namespace serial_robot_driver::devices::servo_bus
