// A device::ServoBus's polls: the scheduled angle poll (servo_states), with the back-off of a
// servo that stops answering, and the health poll (voltage, current, power, temperature, status;
// the servo's own limits read once when it first answers) with ~servo_bus/protect, which relaxes
// a servo at its temperature limit, and the identity read (servo_identity.h: type, firmware,
// serial, response_switch, angle limits), once per servo when it first answers. Every read is
// background work on the bus: it takes the bus only while no caller waits for it, so a caller still
// waits for one transaction at most. ROS-free.
//
// Threading: the schedules are changed by the bus's worker thread (pollOnce) and by retune; they
// are guarded by the bus's one mutex (given at construction), which the methods named ...Locked
// expect held. The bus and the event hooks are called with the mutex released.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <vector>

#include "serial_robot_driver/core/loop_clock.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_client.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_config.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus_events.h"
#include "serial_robot_driver/devices/servo_bus/servo_health.h"

namespace serial_robot_driver::devices::servo_bus {

class ServoPoller {
 public:
  /// A servo that stops answering the poll is asked again after a back-off that doubles from the
  /// first to the longest, so a dead servo costs one timeout per back-off period, not per poll.
  static constexpr std::chrono::milliseconds kFirstBackoff{500};
  static constexpr std::chrono::milliseconds kMaxBackoff{8000};

  struct Hooks {
    /// protect relaxed servo `id` (mutex held, before the relax): none of its queued moves may
    /// follow it.
    std::function<void(uint8_t id)> drop_queued_moves_locked;
    /// protect relaxed servo `id` (mutex released): it is no longer set moving.
    std::function<void(uint8_t id)> relaxed;
  };

  /// `settings`: the bus's settings in force, guarded by `mutex` (poll_rate, health_rate,
  /// protect, relax_power_mw are read there).
  ServoPoller(const std::vector<uint8_t>& ids, const ServoBusConfig& settings,
              ServoBusClient& client, const ServoBusEvents& events, core::LoopClock& clock,
              std::mutex& mutex, Hooks hooks);

  /// When the poll due first falls due (max() when none).
  core::Clock::time_point nextPollLocked() const;
  /// Runs the poll due first, if it is due (mutex held by `lock`, released around the bus):
  /// the health poll before the angle poll.
  void pollDue(std::unique_lock<std::mutex>& lock);
  /// The rates in force changed (settings): an angle poll is due within the new period (a
  /// servo in back-off keeps its back-off), a health poll turned on is due now.
  void retuneLocked(double poll_rate, double health_rate);

  /// One report per polled servo (empty when health_rate is 0).
  std::vector<ServoHealthReport> health() const;
  /// One report per polled servo (known once read; empty when settings.read_identity is off).
  std::vector<ServoIdentityReport> identities() const;
  /// The report of `id` while protect keeps it relaxed; nullptr otherwise.
  const ServoHealthReport* overheatedLocked(uint8_t id) const;
  /// angles_polled, offline_ids and asked_poll_rate into `stats`.
  void addStatsLocked(ServoBusWorkerStats* stats) const;

 private:
  /// One polled servo and its schedule.
  struct PolledServo {
    uint8_t id = 0;
    core::Clock::time_point next_poll;
    std::chrono::milliseconds backoff{0};  ///< 0: online
    /// Its identity: due once it answered the angle poll (max: not due), read once; after a
    /// failed read due again after a back-off of its own, doubling like the angle poll's.
    ServoIdentityReport identity;
    core::Clock::time_point identity_due = core::Clock::time_point::max();
    std::chrono::milliseconds identity_backoff{0};
  };
  /// Its health: one entry per polled servo, changed by the worker only (read under the mutex).
  struct HealthServo {
    ServoHealthReport report;
    core::Clock::time_point next_poll;
    OverheatGuard guard;
  };

  /// The health poll's schedule: the servo due first, and when (max when none).
  core::Clock::time_point nextHealthPollLocked() const;
  void pollAngleOnce(PolledServo& servo);
  void pollHealthOnce(std::size_t index);
  /// The angle poll has the servo in back-off: no bus time for a silent servo.
  bool silentOnAnglePoll(uint8_t id) const;
  /// Stores the readings and judges them (and, with protect, the overheat guard): true when the
  /// servo's overheated state changed.
  bool assessReadings(const std::vector<int64_t>& values, HealthServo* servo);
  /// Relaxes a servo that overheated, as a safety action.
  void relaxOverheated(uint8_t id);
  /// The polled servo whose identity read is due first, or polled_.end().
  std::vector<PolledServo>::iterator identityDueLocked(core::Clock::time_point now);
  void readIdentityOnce(PolledServo& servo);
  /// Reads `names` in order into `values`; the first failure.
  ServoStatus readHealthParams(uint8_t id, const std::vector<const char*>& names,
                               std::vector<int64_t>* values);

  const ServoBusConfig& settings_;
  ServoBusClient& client_;
  const ServoBusEvents& events_;
  core::LoopClock& clock_;
  std::mutex& mutex_;  // the bus's: guards everything below
  const Hooks hooks_;
  core::Clock::duration poll_period_;
  std::vector<PolledServo> polled_;  // schedule changed by the worker (and by retune)
  std::vector<HealthServo> health_;  // one per polled servo; polled while health_period_ > 0
  core::Clock::duration health_period_{0};
  uint64_t angles_polled_ = 0;
  const bool read_identity_;
};

}  // namespace serial_robot_driver::devices::servo_bus
