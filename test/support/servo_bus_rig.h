// The ServoBus test rig: a bus on a manual clock (the worker thread runs; the test moves time)
// over a fake bus that records every frame, answers synchronously with golden frames (scripted
// in order, or one per request), can hold a frame "on the wire" until the test releases it, and
// can be unplugged.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "support/golden_frames.h"
#include "support/manual_clock.h"

namespace serial_robot_driver::devices::servo_bus {

using Bytes = std::vector<uint8_t>;

/// Polls `condition` until it holds or a generous timeout passes (threads of the bus run on).
inline bool waitFor(const std::function<bool()>& condition) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!condition() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return condition();
}

inline SpinRequest continuousSpin0() {
  SpinRequest spin;
  spin.id = 0;
  spin.mode = 1;
  spin.speed_dps = 100;
  return spin;
}

/// ROTATE servo 2 to 90.0 deg in 500 ms (golden::servo::kRotate2To90In500 on the wire).
inline MoveRequest rotate2To90In500() {
  MoveRequest move;
  move.id = 2;
  move.angle_deg = 90.0;
  move.interval_ms = 500;
  return move;
}

/// A ServoBus on a manual clock over a fake bus (see the file comment).
class ServoBusTest : public ::testing::Test {
 protected:
  /// A bus polling `polled_ids` at 10 Hz (every 100 ms) on the manual clock, without the health
  /// poll and the identity read (these tests count the frames of the moves and the angle polls)
  /// unless `configure` turns them on.
  void makeBus(std::vector<uint8_t> polled_ids,
               const std::function<void(ServoBusConfig&)>& configure = {}) {
    ServoBusConfig config;
    config.health_rate = 0.0;
    config.read_identity = false;
    config.client.timeout = std::chrono::milliseconds(5);  // a silent servo costs 5 ms of real time
    config.client.retries = 0;
    config.polled_ids = std::move(polled_ids);
    config.poll_rate = 10.0;
    if (configure) configure(config);
    ServoBusEvents events;
    events.on_angle = [this](const ServoAngleSample& sample) {
      std::lock_guard<std::mutex> lock(mutex_);
      angles_.push_back(sample);
    };
    events.on_servo_silent = [this](uint8_t id, const ServoStatus&,
                                    std::chrono::milliseconds backoff) {
      std::lock_guard<std::mutex> lock(mutex_);
      silent_.push_back({id, backoff});
    };
    events.on_move_failed = [this](const MoveRequest& move, const ServoStatus& status) {
      std::lock_guard<std::mutex> lock(mutex_);
      failed_moves_.push_back({move.id, status.error});
    };
    events.on_stop = [this](uint8_t id, const ServoStatus& status) {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_events_.push_back({id, status});
    };
    events.on_identity = [this](const ServoIdentityReport& report) {
      std::lock_guard<std::mutex> lock(mutex_);
      identities_.push_back(report);
    };
    bus_ = std::make_unique<ServoBus>(
        config, [this](const Bytes& frame) { return write(frame); }, events, clock_);
  }

  bool write(const Bytes& frame) {
    Bytes reply;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (port_down_) return false;  // the cable is out: nothing reaches the bus
      written_.push_back(frame);
      // A gated frame stays "on the wire" (the writer does not return) until the test opens it.
      gate_opened_.wait(lock, [&] { return frame != gated_frame_; });
      auto scripted = scripted_answers_.find(frame);
      if (scripted != scripted_answers_.end() && !scripted->second.empty()) {
        reply = scripted->second.front();  // one answer per request, in order
        scripted->second.pop_front();
      } else {
        auto it = answers_.find(frame);
        if (it == answers_.end()) return true;
        reply = it->second;
      }
    }
    bus_->onFrame(kResponseFrames, reply.data(), reply.size(), core::Clock::now());
    return true;
  }

  std::vector<Bytes> written() {
    std::lock_guard<std::mutex> lock(mutex_);
    return written_;
  }
  /// Where `frame` was first written, or written().size() when it was not.
  std::size_t firstIndexOf(const Bytes& frame) {
    const std::vector<Bytes> all = written();
    return static_cast<std::size_t>(std::find(all.begin(), all.end(), frame) - all.begin());
  }
  void holdOnTheWire(const Bytes& frame) {
    std::lock_guard<std::mutex> lock(mutex_);
    gated_frame_ = frame;
  }
  /// A PING of servo 3 that holds the bus (its frame held on the wire) until releaseTheWire():
  /// the one transaction in flight. Returns its thread, once the frame is written.
  std::thread holdTheBusWithPing3() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      answers_[golden::servo::kPing3] = golden::servo::kPing3Reply;
    }
    holdOnTheWire(golden::servo::kPing3);
    std::thread holder([this] { bus_->client().ping(3); });
    EXPECT_TRUE(waitFor([&] { return countWritten(golden::servo::kPing3) == 1; }));
    return holder;
  }
  void releaseTheWire() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      gated_frame_.clear();
    }
    gate_opened_.notify_all();
  }
  /// Runs `call` on a thread of its own while holdTheBusWithPing3() holds the bus; true once the
  /// call waits for the bus. releaseTheWireAndJoin() lets both finish.
  bool callWaitingBehindPing3(std::function<void()> call) {
    holder_ = holdTheBusWithPing3();
    caller_ = std::thread(std::move(call));
    return waitFor([&] { return bus_->client().callersWaiting() == 1; });
  }
  /// Starts the bus with rotate2To90In500() queued while holdTheBusWithPing3() holds the bus; true
  /// once the worker waits for the bus with the move. releaseTheWireAndJoin() lets it go on.
  bool moveQueuedBehindPing3() {
    holder_ = holdTheBusWithPing3();
    bus_->start();
    bus_->queueMoves({rotate2To90In500()});
    return waitFor([&] { return bus_->client().callersWaiting() == 1; });
  }
  /// Opens the wire and joins the threads of callWaitingBehindPing3() / moveQueuedBehindPing3().
  void releaseTheWireAndJoin() {
    releaseTheWire();
    holder_.join();
    if (caller_.joinable()) caller_.join();
  }
  void setPortDown(bool down) {
    std::lock_guard<std::mutex> lock(mutex_);
    port_down_ = down;
  }
  /// Starts the bus, spins servo 0 and engages the e-stop with the port down (its stop cannot be
  /// written); false when the spin failed.
  bool spinThenEStopWithThePortDown() {
    makeBus({});
    bus_->start();
    clock_->waitForLoop();
    if (!bus_->spin(continuousSpin0()).ok()) return false;
    setPortDown(true);
    clock_->step([&] { bus_->setMotionLocked(true); });
    return true;
  }
  /// The port back up. The reader thread's onLinkUp comes before any write on the reopened port
  /// can succeed.
  void portBackUp() {
    setPortDown(false);
    clock_->step([&] { bus_->onLinkUp(); });
  }
  std::size_t countWritten(const Bytes& frame) {
    std::size_t count = 0;
    for (const Bytes& f : written()) count += f == frame ? 1 : 0;
    return count;
  }

  const core::Clock::time_point t0_ = core::Clock::time_point() + std::chrono::hours(1);
  std::shared_ptr<core::ManualClock> clock_ = std::make_shared<core::ManualClock>(t0_);
  std::mutex mutex_;
  std::map<Bytes, Bytes> answers_ = {
      {golden::servo::kReadAngle0, golden::servo::kReadAngle0Reply902}};
  std::vector<Bytes> written_;
  std::vector<ServoAngleSample> angles_;
  std::vector<std::pair<uint8_t, std::chrono::milliseconds>> silent_;
  std::vector<std::pair<uint8_t, ServoError>> failed_moves_;
  std::vector<std::pair<uint8_t, ServoStatus>> stop_events_;
  std::vector<ServoIdentityReport> identities_;          // on_identity reports
  std::map<Bytes, std::deque<Bytes>> scripted_answers_;  // before answers_, used up in order
  bool port_down_ = false;                               // guarded by mutex_
  std::unique_ptr<ServoBus> bus_;
  std::condition_variable gate_opened_;
  Bytes gated_frame_;   // guarded by mutex_
  std::thread holder_;  // the held PING of callWaitingBehindPing3() / moveQueuedBehindPing3()
  std::thread caller_;  // the call of callWaitingBehindPing3()
};

}  // namespace serial_robot_driver::devices::servo_bus
