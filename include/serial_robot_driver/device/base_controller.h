// The AP1 wheeled base as the driver sees it: cmd_vel in, wheel-speed frames out at the loop rate,
// the 1 s heartbeat, the Reset/timeout-error cycle, battery polling and encoder clearing.
// ROS-free: the ROS layer feeds commands in and publishes the events it reports.
//
// Threading model:
//  - start() runs the control loop on its own thread: absolute deadlines on the LoopClock (the
//    steady clock unless a test passes its own) (deadline += period, never "sleep one period"), so
//    the period does not drift. Each tick writes
//    the current wheel frame, which is also the heartbeat.
//  - setCommand() (cmd_vel callback) only stores the command and wakes the loop, which puts it on
//    the wire at once, at most at twice the loop rate. Callbacks never touch the port.
//  - onFrame() runs on the port's reader thread: an FF error frame wakes the loop to send a Reset.
//  - Every base write happens with mutex_ held, so the sequence counter and "Reset before the next
//    speed frame" are consistent whichever thread writes (loop, or a base/* service).
//  - The BaseEvents hooks are called without mutex_ held, on the thread that caused them (loop,
//    reader, or the caller of stop()). Stats are one struct under mutex_; stats() is a snapshot.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "serial_robot_driver/device/serial_link.h"
#include "serial_robot_driver/kinematics/diff_drive.h"
#include "serial_robot_driver/protocol/base_codec.h"

namespace serial_robot_driver::device {

struct BaseConfig {
  kinematics::DiffDriveGeometry geometry;
  double max_wheel_speed = 1.0;    ///< m/s; <= 0: no clamp
  double max_wheel_accel = 0.0;    ///< m/s^2; 0: no limit
  double cmd_vel_timeout = 0.5;    ///< s without a command: zero speed
  bool speed_dithering = true;     ///< carry the tick remainder (false: vendor truncation)
  double battery_poll_rate = 1.0;  ///< Hz; 0: never ask
  double loop_rate = 50.0;         ///< Hz
  double heartbeat_gap = 1.0;      ///< s; a gap this long in our sending means the base timed out
};

/// One wheel frame as written.
struct WheelFrameSent {
  kinematics::WheelTicks ticks;
  uint8_t seq = 0;
  bool reset_before = false;
  kinematics::WheelSpeeds speeds = kinematics::WheelSpeeds::Zero();  ///< m/s the ticks stand for
  Clock::time_point time;
};

struct BaseStats {
  uint64_t speed_frames = 0;
  uint64_t immediate_frames = 0;     ///< speed frames sent at once for a new cmd_vel
  uint64_t resets_sent = 0;
  uint64_t battery_requests = 0;
  uint64_t clear_encoders_sent = 0;
  uint64_t write_failures = 0;
  uint64_t timeout_errors_received = 0;  ///< FF frames from the base
  uint64_t battery_replies = 0;
  uint64_t unknown_replies = 0;
  uint64_t bad_replies = 0;
  uint64_t cmd_vel_timeouts = 0;
  uint64_t rejected_commands = 0;    ///< NaN/Inf cmd_vel
  uint64_t loop_overruns = 0;        ///< ticks that started more than one period late
  double last_period_ms = 0;
  double worst_period_ms = 0;
  std::optional<uint8_t> battery_percent;
};

/// Where the base loop reads the time and waits for its next tick. The default is the steady
/// clock; tests pass a clock they move themselves.
class LoopClock {
 public:
  virtual ~LoopClock() = default;
  virtual Clock::time_point now() const = 0;
  /// Called by the loop with `lock` (the controller's mutex) held: waits on `wake` until
  /// `deadline` on this clock or a notification, whichever comes first. May return early; the
  /// loop checks again.
  virtual void waitUntil(std::unique_lock<std::mutex>& lock, std::condition_variable& wake,
                         Clock::time_point deadline) = 0;
};

/// What the base reports; every hook may be empty. Called without the controller's lock held.
struct BaseEvents {
  std::function<void(const WheelFrameSent&)> on_wheel_frame;
  /// `arrival`: when the reply's last byte was read (its stamp).
  std::function<void(uint8_t percent, Clock::time_point arrival)> on_battery;
  std::function<void(const protocol::base::Frame&)> on_unknown_reply;
  std::function<void()> on_timeout_error;
};

class BaseController : public LinkListener {
 public:
  /// `clock` empty: the steady clock.
  BaseController(BaseConfig config, FrameWriter writer, BaseEvents events = {},
                 std::shared_ptr<LoopClock> clock = {});
  ~BaseController() override;

  /// Stores a cmd_vel. NaN/Inf components are rejected: zero speed is commanded and false returned.
  bool setCommand(double linear_x, double angular_z);
  /// Writes a Reset now (base/reset). False when the port is down.
  bool sendReset();
  /// Writes a clear-encoders frame now (base/clear_encoders). False when the port is down.
  bool sendClearEncoders();

  void start();
  /// Stops the loop and writes one zero-speed frame, so the robot stops before the port closes.
  void stop();

  BaseStats stats() const;

  // LinkListener (reader thread)
  void onLinkUp() override;
  void onLinkDown() override;
  void onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
               Clock::time_point arrival) override;

 private:
  void run();
  /// A scheduled tick: battery poll when due, then the wheel frame.
  void tick(Clock::time_point now);
  /// Sends the wheel frame for the current command (Reset first when needed).
  void sendSpeed(Clock::time_point now, bool immediate);
  /// Requires mutex_. Writes one frame with the next SEQ; false on failure.
  bool writeLocked(const std::vector<uint8_t>& frame, Clock::time_point now);
  kinematics::WheelSpeeds targetSpeedsLocked(Clock::time_point now);

  const BaseConfig config_;
  const FrameWriter writer_;
  const BaseEvents events_;
  const std::shared_ptr<LoopClock> clock_;
  const Clock::duration period_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  bool stopped_ = false;
  bool command_pending_ = false;  ///< a new cmd_vel or an FF error wants an early frame
  protocol::base::SequenceCounter seq_;
  kinematics::AccelerationLimiter limiter_;
  kinematics::TickQuantizer quantizer_;
  double linear_x_ = 0;
  double angular_z_ = 0;
  std::optional<Clock::time_point> last_command_;
  bool command_timed_out_ = true;
  bool needs_reset_ = true;
  std::optional<Clock::time_point> last_write_;        ///< any base frame
  std::optional<Clock::time_point> last_speed_frame_;
  std::optional<Clock::time_point> last_tick_;
  Clock::time_point next_battery_poll_{};
  BaseStats stats_;
  std::thread loop_;
};

}  // namespace serial_robot_driver::device
