#include "serial_robot_driver/devices/servo_bus/servo_bus.h"

#include <algorithm>
#include <utility>

#include "serial_robot_driver/devices/servo_bus/servo_joint_commands.h"

namespace serial_robot_driver::devices::servo_bus {

ServoBus::ServoBus(ServoBusConfig config, core::FrameWriter writer, ServoBusEvents events,
                   std::shared_ptr<core::LoopClock> clock)
    : config_(std::move(config)),
      settings_(config_),
      events_(std::move(events)),
      clock_(clock ? std::move(clock) : core::steadyLoopClock()),
      client_(config_.client, std::move(writer)),
      poller_(config_.polled_ids, settings_, client_, events_, *clock_, mutex_,
              {[this](uint8_t id) { dropQueuedMovesLocked(id); },
               [this](uint8_t id) { safety_.noteMotion(id, false); }}),
      stops_(client_, events_, *clock_, mutex_,
             [this](uint8_t id) { safety_.noteStopWrittenLocked(id); }),
      safety_(config_.polled_ids, settings_, client_, events_, *clock_, mutex_, stops_, poller_,
              {[this] { queued_moves_.clear(); }, [this] { deliverStops(); }}) {
  client_.setMotionGate(&safety_.gate(), [this](uint8_t id) { safety_.noteCommanded(id); });
}

ServoBus::~ServoBus() { shutdown(); }

void ServoBus::onLinkDown() { client_.onLinkDown(); }

void ServoBus::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                       core::Clock::time_point arrival) {
  client_.onFrame(family, data, size, arrival);
}

void ServoBus::queueMoves(const std::vector<MoveRequest>& moves) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // The e-stop holds: the caller refused (and counted) it already.
    if (safety_.motionLockedLocked()) return;
    // Under mutex_: an e-stop engaged after this note drops the queue (or voids the write).
    const core::MotionGate::Generation accepted = safety_.gate().generation();
    for (const MoveRequest& move : moves) {
      auto queued = std::find_if(queued_moves_.begin(), queued_moves_.end(),
                                 [&move](const QueuedMove& q) { return q.move.id == move.id; });
      if (queued != queued_moves_.end()) {
        *queued = {move, accepted};
        ++stats_.moves_replaced;
      } else {
        queued_moves_.push_back({move, accepted});
      }
    }
  }
  wakeWorker();
}

void ServoBus::dropQueuedMoves(uint8_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  dropQueuedMovesLocked(id);
}

void ServoBus::dropQueuedMovesLocked(uint8_t id) {
  queued_moves_.erase(std::remove_if(queued_moves_.begin(), queued_moves_.end(),
                                     [id](const QueuedMove& q) { return q.move.id == id; }),
                      queued_moves_.end());
}

void ServoBus::retune(const ServoBusConfig& next) {
  client_.retune(next.client);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    static_cast<ServoClientTuning&>(settings_.client) = next.client;
    static_cast<ServoBusTuning&>(settings_) = next;
    poller_.retuneLocked(next.poll_rate, next.health_rate);
  }
  wakeWorker();  // the worker may be waiting for a poll that is now due earlier
}

void ServoBus::start() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (started_ || stop_) return;
    started_ = true;
    if (link_ == nullptr) worker_ = std::thread([this] { workerLoop(); });
  }
  if (link_ != nullptr) link_->wake();  // the reader thread takes the work from now on
}

void ServoBus::shutdown() {
  // The last words are decided from here on: no motion frame passes any more, whoever waited.
  safety_.closeGate();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wakeWorker();
  // The worker's poll is one background transaction at most.
  if (worker_.joinable()) worker_.join();
  {
    // Running on the link's reader thread: the piece of work in progress ends first.
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait(lock, [this] { return !working_; });
  }
  safety_.finalWords();
  client_.shutdown();  // every later call fails at once
}

ServoBusConfig ServoBus::settings() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return settings_;
}

ServoBusWorkerStats ServoBus::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  ServoBusWorkerStats stats = stats_;
  poller_.addStatsLocked(&stats);
  return stats;
}

void ServoBus::runOn(core::SerialLink& link) {
  link_ = &link;
  link.addListener(this);
  link.setWorker(this);
  client_.setReaderPump({[&link] { return link.onReaderThread(); },
                         [&link](core::Clock::time_point until) { return link.pump(until); },
                         [&link] { link.wake(); }});
}

void ServoBus::wakeWorker() {
  wake_.notify_all();
  if (link_ != nullptr) link_->wake();
}

core::Clock::time_point ServoBus::nextWorkLocked() const {
  if (!started_ || stop_) return core::Clock::time_point::max();
  if (!queued_moves_.empty()) return core::Clock::time_point::min();
  return std::min(stops_.nextWorkLocked(), poller_.nextPollLocked());
}

core::Clock::time_point ServoBus::nextWork() {
  std::lock_guard<std::mutex> lock(mutex_);
  return nextWorkLocked();
}

void ServoBus::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!started_ || stop_) return;
  working_ = true;
  workOnce(lock);
  working_ = false;
  lock.unlock();
  wake_.notify_all();  // shutdown() waits for the piece of work in progress
}

void ServoBus::workerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    core::Clock::time_point due = nextWorkLocked();
    // Nothing scheduled: wait to be woken (bounded, so the clock's arithmetic cannot overflow).
    if (due == core::Clock::time_point::max()) due = clock_->now() + std::chrono::hours(1);
    if (clock_->now() < due) {
      clock_->waitUntil(lock, wake_, due);
    } else {
      workOnce(lock);
    }
  }
}

void ServoBus::workOnce(std::unique_lock<std::mutex>& lock) {
  // Stops first: nothing else this bus does may go before them.
  if (stops_.workOnce(lock, StopPace::kScheduled)) return;
  if (!queued_moves_.empty()) {
    const QueuedMove queued = queued_moves_.front();
    queued_moves_.pop_front();
    lock.unlock();
    sendMove(queued);
    lock.lock();
    return;
  }
  poller_.pollDue(lock);
}

void ServoBus::sendMove(const QueuedMove& queued) {
  const MoveRequest& move = queued.move;
  ServoStatus status = safety_.refusal(move.id);  // an overheated servo (protect)
  if (status.ok()) {
    // Through the motion gate: refused if an e-stop engaged since it was queued.
    status = client_.move(move, BusPriority::kWorker, queued.accepted);
  }
  if (status.error == ServoError::kPreempted) {
    // A stop goes first; the move goes after it unless a newer target or the e-stop replaced it.
    std::lock_guard<std::mutex> lock(mutex_);
    const bool replaced =
        std::any_of(queued_moves_.begin(), queued_moves_.end(),
                    [&move](const QueuedMove& q) { return q.move.id == move.id; });
    if (!replaced && !safety_.motionLockedLocked() && !stops_.keptLocked(move.id)) {
      queued_moves_.push_front(queued);
    }
    return;
  }
  if (status.ok()) safety_.noteMotion(move.id, true);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status.ok()) {
      ++stats_.moves_sent;
    } else {
      ++stats_.moves_failed;
    }
  }
  if (!status.ok() && events_.on_move_failed) events_.on_move_failed(move, status);
}

// The e-stop and the stops: the policy is the MotionSafety's, the delivery the worker's.

void ServoBus::setMotionLocked(bool locked) { safety_.setMotionLocked(locked); }

void ServoBus::stopServo(uint8_t id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    dropQueuedMovesLocked(id);
    // Under the e-stop it is the e-stop's: repeated while it holds.
    stops_.armLocked(id, clock_->now(), safety_.motionLockedLocked());
  }
  deliverStops();
}

void ServoBus::deliverStops() {
  bool worker_running = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    worker_running = started_ && !stop_;
  }
  if (worker_running) {
    stops_.askUrgent();  // nobody takes the bus before the worker has written them
    wakeWorker();
    return;
  }
  // No worker (before start()): write them here; their confirmation waits for the worker.
  std::unique_lock<std::mutex> lock(mutex_);
  stops_.writeDue(lock, StopPace::kNow);
}

void ServoBus::onLinkUp() {
  // On the reader thread, before any write on the reopened port can succeed: the stops go first.
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!safety_.rearmStopsLocked(clock_->now()) || !started_ || stop_) return;
  }
  stops_.askUrgent();
  wakeWorker();  // a worker of its own; on the link, this thread is the worker
}

// Motion through the device: the MotionSafety's.

ServoStatus ServoBus::move(const MoveRequest& request) { return safety_.move(request); }
ServoStatus ServoBus::rotate(const RotateRequest& request) { return safety_.rotate(request); }
ServoStatus ServoBus::spin(const SpinRequest& request) { return safety_.spin(request); }
ServoStatus ServoBus::damping(uint8_t id, uint16_t power_mw, bool wait) {
  return safety_.damping(id, power_mw, wait);
}
ServoStatus ServoBus::relax(const std::vector<uint8_t>& ids) { return safety_.relax(ids); }
ServoStatus ServoBus::hold(const std::vector<uint8_t>& ids) { return safety_.hold(ids); }
ServoStatus ServoBus::writeParam(uint8_t id, std::string_view param, int64_t value) {
  return safety_.writeParam(id, param, value);
}
ServoStatus ServoBus::resetUserData(uint8_t id) { return safety_.resetUserData(id); }
bool ServoBus::motionLocked() const { return safety_.motionLocked(); }
std::vector<uint8_t> ServoBus::movingIds() const { return safety_.movingIds(); }
std::string ServoBus::motionInForce() const {
  const std::vector<uint8_t> moving = movingIds();
  if (moving.empty()) return {};
  return "servo(s) " + servoIdList(moving) +
         " set moving and not stopped since (servo/spin mode 0, servo/hold or servo/relax stops "
         "them)";
}
std::vector<uint8_t> ServoBus::commandedIds() const { return safety_.commandedIds(); }
std::vector<PendingStopReport> ServoBus::pendingStops() const { return stops_.reports(); }
std::vector<ServoHealthReport> ServoBus::health() const { return poller_.health(); }
std::vector<ServoIdentityReport> ServoBus::identities() const { return poller_.identities(); }

}  // namespace serial_robot_driver::devices::servo_bus
