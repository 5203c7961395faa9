// Simulated chain of UART bus servos (docs/protocols.md, section 3).
//
// Each servo keeps the full parameter table: read-only values that drift a little (voltage,
// temperature, ...) and the 32-byte user block, persistent across requests. Motions (ROTATE, SPIN,
// and the newer CMD 11..15 moves with their accel/decel ramps) run in simulated time on a
// trapezoidal speed profile. Each servo keeps a multi-turn angle: READ_ANGLE reports it folded into
// one turn, CMD 16 reports it whole with its turn count; a single-turn move starts from the folded
// angle (assumption: the datasheet does not say). RESET_USER_DATA restores the factory user block,
// id 0 included, and answers from id 0. Answers leave after a small latency; the optional
// SPIN/ROTATE/DAMPING answers only when response_switch is 1, and only once the motion has
// completed. Requests that reach no present servo, broadcasts (id 255) and READ_DATA of an unknown
// data_id get no answer.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <random>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus_codec.h"
#include "serial_robot_driver/sim/sim_options.h"
#include "serial_robot_driver/sim/sim_stats.h"
#include "serial_robot_driver/sim/sim_types.h"

namespace serial_robot_driver::devices::servo_bus::sim {

struct ServoBusSimConfig {
  std::vector<uint8_t> servo_ids = {0, 1, 2};
  std::vector<uint8_t> offline_ids;  ///< listed servos that never answer
  /// Servos whose temperature (degC) or voltage (mV) is held at a value instead of drifting.
  std::map<uint8_t, int64_t> temperature_c;
  std::map<uint8_t, int64_t> voltage_mv;
  /// A servo's identity and response_switch where they differ from every other's (servo_type
  /// 257, firmware_version 258, serial_number 0x53520000 + id, response_switch 0): another model,
  /// another firmware, or motions queued and answered (response_switch 1).
  std::map<uint8_t, int64_t> servo_type;
  std::map<uint8_t, int64_t> firmware_version;
  std::map<uint8_t, int64_t> serial_number;
  std::map<uint8_t, int64_t> response_switch;
  double answer_latency_s = 0.0015;
  /// The next this many SPIN stops (mode 0) addressed to a servo never reach it, as if lost on
  /// the line: the driver must notice the servo still moves and stop it again.
  uint32_t lost_stops = 0;
  uint32_t seed = 1;
  /// --servo-fault-rate: the probability robot_sim garbles an answer on the line (half the time)
  /// or loses it (the other half).
  double answer_fault_rate = 0.0;
};

struct BusServoSnapshot {
  uint8_t id = 0;
  double angle_deg = 0.0;
  bool moving = false;
  bool relaxed = false;  ///< DAMPING since the last motion command: no holding torque
  /// Every parameter by data_id (read-only ones included).
  std::map<uint8_t, int64_t> params;
};

struct ServoBusSimStats {
  uint64_t requests = 0;  ///< verified request packets
  uint64_t answers = 0;   ///< answers emitted
  uint64_t broadcasts = 0;
  uint64_t unaddressed = 0;  ///< for an id no present servo has (offline ids included)
  uint64_t unknown_data_ids = 0;
  uint64_t malformed = 0;        ///< verified sum but content that does not fit the command
  uint64_t writes_rejected = 0;  ///< answered with result 0
  uint64_t stops_lost = 0;       ///< SPIN stops dropped by lost_stops
  std::vector<BusServoSnapshot> servos;
};

/// The servos' answers: checksum in the last byte.
extern const serial_robot_driver::sim::OutputKind kServoAnswerOutput;

class ServoBusSim {
 public:
  ServoBusSim(const ServoBusSimConfig& config, serial_robot_driver::sim::TimePoint now);

  /// A sum-verified 12 4C request from the host.
  void handleRequest(const uint8_t* data, std::size_t size,
                     serial_robot_driver::sim::TimePoint now);
  /// Runs motions and emits the answers that are due.
  void tick(serial_robot_driver::sim::TimePoint now, serial_robot_driver::sim::Outbox* out);
  serial_robot_driver::sim::TimePoint nextEvent() const;

  ServoBusSimStats stats() const;

 private:
  /// A finite motion: a move to an angle (ROTATE, CMD 11..15), or a SPIN for some turns or ms.
  struct Motion {
    enum class Kind { kRotate, kSpin } kind = Kind::kRotate;
    double target_angle = 0.0;  ///< kRotate
    bool multi_turn = false;    ///< kRotate: starts from the whole angle, not the folded one
    double velocity_dps = 0.0;  ///< kRotate by velocity (> 0): the duration follows at the start
    double accel_s = 0.0;       ///< kRotate ramps
    double decel_s = 0.0;
    double peak_dps = 0.0;  ///< kRotate: the cruise speed, set when the motion starts
    double rate_dps = 0.0;  ///< kSpin, signed (counter-clockwise positive)
    double duration_s = 0.0;
    bool started = false;
    double start_angle = 0.0;
    serial_robot_driver::sim::TimePoint start;
    bool answer = false;  ///< response_switch was 1 when it was requested
    uint8_t answer_id = 0;
    servo_bus::Command cmd = servo_bus::Command::kRotate;
  };
  struct Servo {
    double angle_deg = 0.0;
    double spin_rate_dps = 0.0;  ///< continuous SPIN in force
    std::map<uint8_t, int64_t> params;
    std::deque<Motion> motions;  ///< front runs; the rest are queued (response_switch 1)
    serial_robot_driver::sim::TimePoint last_step;
    bool relaxed = false;  ///< DAMPING since the last motion command
  };
  struct PendingAnswer {
    serial_robot_driver::sim::TimePoint due;
    std::vector<uint8_t> bytes;
  };

  /// A request that fits its command, as one servo's handler sees it.
  struct Request {
    Servo* servo;
    const Packet& packet;
    servo_bus::Command cmd;
    uint8_t id;      ///< as addressed (the broadcast id included)
    bool broadcast;  ///< to every servo
    bool answers;    ///< this servo answers it: not broadcast, and the command table says so
    serial_robot_driver::sim::TimePoint now;
    serial_robot_driver::sim::TimePoint due;  ///< when its answer leaves
  };
  using Handler = void (ServoBusSim::*)(const Request& request);
  struct HandlerRow {
    servo_bus::Command cmd;
    Handler handle;
  };
  /// The handler of each command, row for row as commandTable().
  static const std::array<HandlerRow, kMaxCommand>& handlers();

  void resetUserData(Servo* servo) const;
  /// Checks the request's size against the command table and hands it to its command's handler.
  void execute(Servo* servo, const Packet& packet, bool broadcast,
               serial_robot_driver::sim::TimePoint now);
  /// Queues the answer when the servo answers this request.
  void reply(const Request& request, const std::vector<uint8_t>& content);
  void onPing(const Request& request);
  void onResetUserData(const Request& request);
  /// READ_DATA / WRITE_DATA: the parameter the request names and its content; nullptr (counted)
  /// when malformed or unknown.
  const ParamInfo* dataRequest(const Request& request, DataContent* content);
  void onReadData(const Request& request);
  void onWriteData(const Request& request);
  void onReadBatchData(const Request& request);
  void onWriteBatchData(const Request& request);
  void onSpin(const Request& request);
  /// ROTATE and CMD 11..15.
  void onMove(const Request& request);
  void onDamping(const Request& request);
  void onReadAngle(const Request& request);
  void onReadMultiTurnAngle(const Request& request);
  void answer(serial_robot_driver::sim::TimePoint due, servo_bus::Command cmd,
              const std::vector<uint8_t>& content);
  /// Response_switch 0 interrupts whatever runs; 1 queues behind it and answers at completion.
  void startMotion(Servo* servo, Motion motion, serial_robot_driver::sim::TimePoint now);
  void stopAll(Servo* servo);
  void runMotions(Servo* servo, serial_robot_driver::sim::TimePoint now);
  /// Sets up the speed profile of a move from the servo's current angle.
  static void beginMove(Motion* motion, double start_angle);
  /// Where a move is `elapsed` seconds after its start.
  static double moveAngle(const Motion& motion, double elapsed);
  /// A move command (ROTATE, CMD 11..15): clamps to the angle limits and starts or queues it.
  void requestMove(Servo* servo, Motion motion, uint8_t id, bool broadcast,
                   serial_robot_driver::sim::TimePoint now);
  void driftReadOnly(Servo* servo);
  static int64_t param(const Servo& servo, uint8_t data_id);

  ServoBusSimConfig config_;
  ServoBusSimStats stats_;
  std::vector<Servo> servos_;
  std::deque<PendingAnswer> pending_;  ///< ordered by due time
  std::mt19937 rng_;
  serial_robot_driver::sim::TimePoint last_drift_;
};

/// The servo bus's settings in robot_sim's options (made with their defaults on first use).
ServoBusSimConfig& servoBusConfig(serial_robot_driver::sim::SimOptions& options);
/// The servo bus's counters in a stats snapshot (all zero when it was not simulated).
const ServoBusSimStats& servoBusStats(const serial_robot_driver::sim::SimStats& stats);
/// The same of a temporary snapshot (servoBusStats(robot.stats())): a copy, which outlives it.
ServoBusSimStats servoBusStats(serial_robot_driver::sim::SimStats&& stats);

}  // namespace serial_robot_driver::devices::servo_bus::sim
