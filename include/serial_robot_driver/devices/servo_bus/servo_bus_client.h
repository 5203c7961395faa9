// The operations of the UART bus servos (docs/protocols.md, section 3) as typed calls: queries
// (PING, scan, angles), parameters (READ_DATA / WRITE_DATA with their checks and read-back,
// READ_BATCH_DATA, RESET_USER_DATA) and motions (servo/move, ROTATE, SPIN, DAMPING), each checked
// before anything is written, over the transaction client (servo_transactions.h, which has the
// threading model). ROS-free; device::ServoBus (servo_bus.h) owns one, with the queue and the
// poll, and the ROS services (ros/servo_bus_ros.h) call its operations.
//
// Threading: any thread; the transaction client serializes the calls on the bus.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/motion_gate.h"
#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/bus_mutex.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/devices/servo_bus/servo_move.h"
#include "serial_robot_driver/devices/servo_bus/servo_params.h"
#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

namespace serial_robot_driver::devices::servo_bus {

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
  uint16_t power_mw = 0;  ///< 0: the servo's default
  /// Wait for the completion answer (sent only when response_switch = 1) up to
  /// interval_ms + timeout; never re-sent.
  bool wait = false;
  /// kCaller, or kStop for a stop service (servo/hold): see BusPriority.
  BusPriority priority = BusPriority::kCaller;
};

struct SpinRequest {
  uint8_t id = 0;
  bool clockwise = false;
  uint8_t mode = 0;  ///< 0 stop, 1 continuous, 2 `value` turns, 3 `value` ms
  uint16_t speed_dps = 0;
  uint16_t value = 0;
  /// Wait for the completion answer (response_switch = 1) up to the expected duration (mode 2:
  /// value * 360 / speed_dps s, mode 3: value ms, else 0) + timeout; never re-sent.
  bool wait = false;
  /// kCaller, or kStop (servo/spin, served with the stops). A SPIN stop (mode 0) is always kStop.
  BusPriority priority = BusPriority::kCaller;
};

/// A multi-turn angle (CMD 16).
struct MultiTurnReading {
  double angle_deg = 0.0;
  int16_t turns = 0;
};

class ServoBusClient : public core::LinkListener {
 public:
  /// The longest motion a caller may wait for (the longest ROTATE interval).
  static constexpr std::chrono::milliseconds kMaxMotionWait{65535};

  ServoBusClient(ServoBusOptions options, core::FrameWriter writer);

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
  ServoStatus readAngle(uint8_t id, double* angle_deg, core::Clock::time_point* arrival = nullptr,
                        BusPriority priority = BusPriority::kCaller);
  /// CMD 16: the multi-turn angle and the turn count.
  ServoStatus readMultiTurnAngle(uint8_t id, MultiTurnReading* reading);
  /// CMD 8 or 11..15, chosen by the request (see MoveRequest); returns once the frame is written.
  /// `accepted` (every motion): the motion gate's generation the command was accepted under.
  ServoStatus move(const MoveRequest& request, BusPriority priority = BusPriority::kCaller,
                   std::optional<core::MotionGate::Generation> accepted = std::nullopt);
  /// PINGs first_id..last_id, one attempt each (a silent id costs one timeout), and lists the ids
  /// that answered. The bus is taken per id, so other callers are served in between.
  ServoStatus scan(uint8_t first_id, uint8_t last_id, std::vector<uint8_t>* ids);
  /// ROTATE / SPIN / DAMPING return once the frame is written unless `wait` is set. Id 255
  /// (broadcast) is accepted only without wait.
  /// Each motion frame is written through the motion gate (setMotionGate), decided when its turn
  /// on the bus comes: refused then (kMotionRefused), nothing is written. A SPIN stop, and a
  /// DAMPING with FrameGate::kSafetyAction, always pass; one accepted under an earlier
  /// generation than the gate's (`accepted`) is dropped (MotionGate::writeIfOpen).
  /// A SPIN stop and every DAMPING (torque off) take the bus at BusPriority::kStop: after the one
  /// attempt in flight, before every waiting call and poll.
  ServoStatus rotate(const RotateRequest& request,
                     std::optional<core::MotionGate::Generation> accepted = std::nullopt);
  ServoStatus spin(const SpinRequest& request,
                   std::optional<core::MotionGate::Generation> accepted = std::nullopt);
  ServoStatus damping(uint8_t id, uint16_t power_mw, bool wait,
                      FrameGate gate = FrameGate::kMotion);
  /// READ_BATCH_DATA: the 22 user-block parameters (data_id 32..53) in table order.
  ServoStatus readAll(uint8_t id, std::vector<ServoParamValue>* values);
  /// RESET_USER_DATA (dangerous: refused unless allow_dangerous_writes). The reset also sets the
  /// servo's id to its default 0, so the answer may come from id 0 or not at all: without an
  /// answer the client PINGs id 0, and a servo there means the reset worked.
  ServoStatus resetUserData(uint8_t id);

  // The transaction client's controls, for the bus that owns this client.
  /// SPIN stops as urgent work (ServoTransactions::writeStops). Fire and forget: whether the
  /// servo heard it is for the caller to find out.
  void writeStops(const std::vector<uint8_t>& ids, std::vector<bool>* written) {
    transactions_.writeStops(ids, written);
  }
  /// Urgent work is coming (ServoTransactions::requestUrgent): a motion wait gives way.
  void requestUrgent() { transactions_.requestUrgent(); }
  void endUrgent() { transactions_.endUrgent(); }
  /// Wakes a waiting caller and fails every later call with kShutdown. Idempotent.
  void shutdown() { transactions_.shutdown(); }
  ServoBusStats stats() const { return transactions_.stats(); }
  /// The options in force (a copy: retune() may change timeout and retries meanwhile).
  ServoBusOptions options() const { return transactions_.options(); }
  /// A new timeout and retry count for the transactions that start from now on; one that runs
  /// keeps what it started with. Never waits for the bus.
  void retune(const ServoClientTuning& next) { transactions_.retune(next); }
  /// Callers (not background work) waiting for the bus right now (for tests and diagnostics).
  int callersWaiting() { return transactions_.busMutex().foregroundWaiting(); }
  /// Urgent work (stops, BusPriority::kStop calls) waiting for the bus right now (for tests).
  int stopsWaiting() { return transactions_.busMutex().urgentWaiting(); }
  /// Before any call: whether a stop call waits for its thread (see
  /// ServoTransactions::setStopCallsQueued); stopCallQueued() when one was queued.
  void setStopCallsQueued(std::function<bool()> queued) {
    transactions_.setStopCallsQueued(std::move(queued));
  }
  void stopCallQueued() { transactions_.stopCallQueued(); }
  /// Before any call: waits on the pump's reader thread read the port (see servo_transactions.h).
  void setReaderPump(ReaderPump pump) { transactions_.setReaderPump(std::move(pump)); }
  /// Before any call: the gate every motion frame passes when it is written (nullptr: none), and
  /// what is told, under the gate's lock, of each motion frame that went out (the servo's id).
  void setMotionGate(core::MotionGate* gate,
                     std::function<void(uint8_t id)> on_motion_written = {}) {
    transactions_.setMotionGate(gate, std::move(on_motion_written));
  }

  // LinkListener (reader thread): the answers are the transaction client's.
  void onLinkDown() override { transactions_.onLinkDown(); }
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               core::Clock::time_point arrival) override {
    transactions_.onFrame(family, data, size, arrival);
  }

 private:
  using Expectation = ServoTransactions::Expectation;

  /// The shared tail of ROTATE/SPIN/DAMPING: takes the bus at `priority` (kCaller or kStop),
  /// then sends, or transacts and checks the result byte.
  ServoStatus sendMotion(const std::vector<uint8_t>& request, Command cmd, uint8_t id, bool wait,
                         std::chrono::milliseconds motion_time, FrameGate gate,
                         BusPriority priority,
                         std::optional<core::MotionGate::Generation> accepted);

  // The helpers below expect the bus to be held by the caller.
  ServoStatus readParamLocked(uint8_t id, const ParamInfo& param, ServoParamValue* value);
  ServoStatus pingLocked(uint8_t id);
  /// Before servo `id` moves to `new_id`: ok when nothing answers at `new_id`.
  ServoStatus checkIdFreeLocked(uint8_t id, uint8_t new_id);
  /// One PING attempt, no retries (scan, and the check after a silent reset).
  ServoStatus pingOnceLocked(uint8_t id);

  ServoTransactions transactions_;
};

}  // namespace serial_robot_driver::devices::servo_bus
