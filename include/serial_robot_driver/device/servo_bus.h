// The UART servo bus as a device: the client (the wire and its operations), the queue of moves
// from a stream of targets (servo_commands) and the scheduled angle poll (servo_states), with the
// back-off of a servo that stops answering. ROS-free: the ROS layer (ros/servo_bus_interface.h)
// converts messages to calls and events to messages.
//
// Threading model:
//  - start() runs one worker thread. It writes the queued moves first, then polls the servo whose
//    poll falls due first; it waits on the LoopClock (the steady clock unless a test passes its
//    own) until the next poll or a new move. Both take the bus after any waiting caller (the poll
//    as background work), so a service call waits for one transaction at most.
//  - queueMoves() may be called from any thread: it only stores the targets and wakes the worker.
//  - The operations of client() (the services) run on their caller's thread, serialized with the
//    worker by the client's bus lock.
//  - The ServoBusEvents hooks run on the worker thread without mutex_ held.
//  - Stats are one struct under mutex_; stats() returns a snapshot.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/device/loop_clock.h"
#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/device/servo_bus_client.h"

namespace serial_robot_driver::device {

struct ServoBusConfig {
  ServoBusOptions client;
  std::vector<uint8_t> polled_ids;  ///< servos whose angle is polled (servo_states)
  double poll_rate = 10.0;          ///< polls per second of each polled servo, > 0
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

class ServoBus : public LinkListener {
 public:
  /// A servo that stops answering the poll is asked again after a back-off that doubles from the
  /// first to the longest, so a dead servo costs one timeout per back-off period, not per poll.
  static constexpr std::chrono::milliseconds kFirstBackoff{500};
  static constexpr std::chrono::milliseconds kMaxBackoff{8000};

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

  /// Starts the worker thread. Idempotent.
  void start();
  /// Fails a call in progress (kShutdown), stops and joins the worker. Idempotent.
  void shutdown();

  ServoBusWorkerStats stats() const;
  /// The configuration it was built with (retune() changes only what its comment says).
  const ServoBusConfig& config() const { return config_; }
  /// Applies the tunable part of `next`: client.timeout and client.retries from the next bus
  /// transaction on, poll_rate from the next poll on (a faster rate does not wait out the slower
  /// period still pending). Never waits for the bus. Expects validated values (poll_rate > 0).
  void retune(const ServoBusConfig& next);

  // LinkListener (reader thread): handed on to the client.
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point arrival) override;

 private:
  /// One polled servo and its schedule.
  struct PolledServo {
    uint8_t id = 0;
    Clock::time_point next_poll;
    std::chrono::milliseconds backoff{0};  ///< 0: online
  };

  void workerLoop();
  void sendMove(const MoveRequest& move);
  void pollOnce(PolledServo& servo);

  const ServoBusConfig config_;
  const ServoBusEvents events_;
  const std::shared_ptr<LoopClock> clock_;
  Clock::duration poll_period_;  // guarded by mutex_ (retune)
  ServoBusClient client_;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  bool stop_ = false;
  bool started_ = false;
  std::deque<MoveRequest> queued_moves_;
  std::vector<PolledServo> polled_;  // schedule changed by the worker (and by retune)
  ServoBusWorkerStats stats_;
  std::thread worker_;
};

}  // namespace serial_robot_driver::device
