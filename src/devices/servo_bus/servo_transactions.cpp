#include "serial_robot_driver/devices/servo_bus/servo_transactions.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "servo_bus_text.h"

namespace serial_robot_driver::devices::servo_bus {

using namespace servo_text;  // NOLINT: the shared sentences of every servo operation

namespace {

double toMs(core::Clock::duration duration) {
  return std::chrono::duration<double, std::milli>(duration).count();
}

}  // namespace

bool refusesRequest(ServoError error) {
  return error == ServoError::kInvalidArgument || error == ServoError::kUnknownParam ||
         error == ServoError::kReadOnly || error == ServoError::kOutOfRange ||
         error == ServoError::kDangerous;
}

const char* toString(ServoError error) {
  switch (error) {
    case ServoError::kOk:
      return "ok";
    case ServoError::kInvalidArgument:
      return "invalid argument";
    case ServoError::kUnknownParam:
      return "unknown parameter";
    case ServoError::kReadOnly:
      return "read-only parameter";
    case ServoError::kOutOfRange:
      return "value out of range";
    case ServoError::kDangerous:
      return "dangerous write refused";
    case ServoError::kNotConnected:
      return "port not connected";
    case ServoError::kIdInUse:
      return "servo id in use";
    case ServoError::kMotionRefused:
      return "motion refused";
    case ServoError::kTimeout:
      return "timeout";
    case ServoError::kBadAnswer:
      return "malformed answer";
    case ServoError::kRefused:
      return "refused by the servo";
    case ServoError::kReadBackMismatch:
      return "read-back mismatch";
    case ServoError::kShutdown:
      return "shutting down";
    case ServoError::kPreempted:
      return "gave way to a stop";
  }
  return "unknown";
}

ServoTransactions::Expectation::Expectation(Command answer_cmd, uint8_t answer_id)
    : Expectation(answer_cmd, answer_id, commandInfo(answer_cmd).answer.min) {}

ServoTransactions::ServoTransactions(ServoBusOptions options, core::FrameWriter writer)
    : options_(std::move(options)), writer_(std::move(writer)) {}

ServoBusStats ServoTransactions::stats() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return stats_;
}

void ServoTransactions::shutdown() {
  std::lock_guard<std::mutex> lock(state_mutex_);
  stopping_ = true;
  answer_cv_.notify_all();
}

void ServoTransactions::onLinkDown() {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (pending_.active) {
    link_lost_ = true;
    answer_cv_.notify_all();
  }
}

bool ServoTransactions::matches(const Packet& packet) const {
  const Expectation& expect = pending_.expect;
  if (packet.cmd != static_cast<uint8_t>(expect.cmd) || packet.content_size == 0) return false;
  const uint8_t id = packet.id();
  if (id != expect.id && !(expect.alt_id && id == *expect.alt_id)) return false;
  // An answer about another data_id is a late answer to an earlier request, not garbage.
  if (expect.data_id && (packet.content_size < 2 || packet.content[1] != *expect.data_id)) {
    return false;
  }
  return true;
}

void ServoTransactions::onFrame(protocol::FrameFamily family, const uint8_t* data, std::size_t size,
                                core::Clock::time_point arrival) {
  if (family == kRequestFrames) {
    // On a half-duplex adapter our own request comes back: recognise it, skip it.
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (!last_request_.empty() && size == last_request_.size() &&
        std::equal(data, data + size, last_request_.begin())) {
      ++stats_.echoes;
    } else {
      ++stats_.mismatched;  // another host's request: not ours to answer or wait for
    }
    return;
  }
  if (family != kResponseFrames) return;  // another device on this port

  const protocol::Decoded<Packet> packet = decodeResponse(data, size);
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (!packet.ok()) {
      ++stats_.garbled;
      return;
    }
    if (!pending_.active || pending_.answered || pending_.garbled || !matches(*packet)) {
      ++stats_.mismatched;
      return;
    }
    if (packet->content_size != pending_.expect.content_size) {
      ++stats_.garbled;
      pending_.garbled = true;
    } else {
      pending_.answered = true;
    }
    pending_.answer = *packet;
    pending_.arrival = arrival;
  }
  // Notified after the unlock: a caller woken while this thread still held state_mutex_ would
  // only block on it again (one more sleep and wake-up per transaction on a busy bus). Only the
  // transaction's own caller waits, and it cannot leave before its predicate holds.
  answer_cv_.notify_one();
}

void ServoTransactions::setReaderPump(ReaderPump pump) {
  pump_ = std::move(pump);
  bus_mutex_.setReaderPump(pump_.pump ? &pump_ : nullptr);
}

void ServoTransactions::waitForAnswer(std::unique_lock<std::mutex>& lock,
                                      core::Clock::time_point deadline) {
  const auto settled = [this] {
    return pending_.answered || pending_.garbled || link_lost_ || stopping_ ||
           motionWaitCutLocked();
  };
  if (!pump_.pump || !pump_.on_reader_thread()) {
    answer_cv_.wait_until(lock, deadline, settled);
    return;
  }
  // The reader thread reads the answer itself: onFrame() runs inside pump(), on this thread.
  while (!settled() && core::Clock::now() < deadline) {
    lock.unlock();
    const bool port_up = pump_.pump(deadline);
    lock.lock();
    if (!port_up && !settled()) link_lost_ = true;  // down, lost or stopping: no answer can come
  }
}

std::optional<ServoStatus> ServoTransactions::writeRequest(
    const std::vector<uint8_t>& request, Command cmd, uint8_t id, FrameGate gate,
    std::optional<core::MotionGate::Generation> accepted) {
  bool written = false;
  if (gate == FrameGate::kMotion && gate_ != nullptr) {
    const core::GateState state = gate_->writeIfOpen(
        [&] {
          const bool out = writer_(request);
          if (out && on_motion_written_) on_motion_written_(id);
          return out;
        },
        &written, accepted);
    if (state != core::GateState::kOpen) {
      return fail(ServoError::kMotionRefused,
                  std::string(toString(state)) + ": " + commandName(cmd) + " to " + servoName(id) +
                      " was not written (refused when its turn on the bus came)");
    }
  } else {
    written = writer_(request);
  }
  if (!written) return notConnected();
  return std::nullopt;
}

ServoStatus ServoTransactions::transact(const std::vector<uint8_t>& request,
                                        const Expectation& expect,
                                        std::chrono::milliseconds timeout, int attempts,
                                        Packet* answer, FrameGate gate, bool give_way,
                                        core::Clock::time_point* arrival,
                                        std::optional<core::MotionGate::Generation> accepted) {
  bool any_garbled = false;
  std::size_t garbled_size = 0;
  for (int attempt = 1; attempt <= attempts; ++attempt) {
    // A stop asked during the last attempt or transaction (a holder may keep the bus for several)
    // goes first: the worker that writes it ends here, a caller hands the bus over meanwhile.
    if (give_way && bus_mutex_.urgentRequested()) {
      return fail(ServoError::kPreempted,
                  servoName(expect.id) + "'s " + commandName(expect.cmd) + " gave way to a stop");
    }
    bus_mutex_.yieldToUrgent();
    if (!beginAttempt(request, expect, gate)) {
      return fail(ServoError::kShutdown, "servo bus client is shutting down");
    }
    const core::Clock::time_point sent_at = core::Clock::now();
    if (auto refusal = writeRequest(request, expect.cmd, expect.id, gate, accepted)) {
      std::lock_guard<std::mutex> lock(state_mutex_);
      pending_.active = false;
      motion_wait_ = false;
      return *refusal;
    }

    std::unique_lock<std::mutex> lock(state_mutex_);
    if (attempt == 1) {
      ++stats_.transactions;
    } else {
      ++stats_.retries;
    }
    waitForAnswer(lock, sent_at + timeout);
    pending_.active = false;
    if (arrival != nullptr) *arrival = pending_.arrival;
    const bool cut_short = motionWaitCutLocked() && !pending_.answered;
    motion_wait_ = false;

    if (pending_.answered) return answeredLocked(sent_at, answer);
    if (link_lost_) {
      return fail(ServoError::kNotConnected, "servo bus port was lost while waiting for " +
                                                 servoName(expect.id) + "'s " +
                                                 commandName(expect.cmd) + " answer");
    }
    if (stopping_) return fail(ServoError::kShutdown, "servo bus client is shutting down");
    if (cut_short) {
      return fail(ServoError::kPreempted,
                  std::string(commandName(expect.cmd)) + " was written to " + servoName(expect.id) +
                      ", but the wait for its completion was cut short by a stop");
    }
    if (pending_.garbled) {
      any_garbled = true;
      garbled_size = pending_.answer.content_size;
    }
  }

  if (any_garbled) return malformed(expect, garbled_size);
  return timedOut(expect, timeout, attempts);
}

ServoStatus ServoTransactions::answeredLocked(core::Clock::time_point sent_at, Packet* answer) {
  const double latency_ms = toMs(pending_.arrival - sent_at);
  stats_.last_latency_ms = latency_ms;
  stats_.max_latency_ms = std::max(stats_.max_latency_ms, latency_ms);
  *answer = pending_.answer;
  return ok("answered in " + formatMs(latency_ms));
}

ServoStatus ServoTransactions::malformed(const Expectation& expect, std::size_t garbled_size) {
  return fail(ServoError::kBadAnswer,
              servoName(expect.id) + " sent a malformed " + commandName(expect.cmd) + " answer (" +
                  std::to_string(garbled_size) + " content bytes, expected " +
                  std::to_string(expect.content_size) + ")");
}

bool ServoTransactions::beginAttempt(const std::vector<uint8_t>& request, const Expectation& expect,
                                     FrameGate gate) {
  std::lock_guard<std::mutex> lock(state_mutex_);
  if (stopping_) return false;
  pending_ = Pending{};
  pending_.active = true;
  pending_.expect = expect;
  last_request_ = request;
  link_lost_ = false;
  motion_wait_ = gate == FrameGate::kMotion;
  return true;
}

ServoStatus ServoTransactions::timedOut(const Expectation& expect,
                                        std::chrono::milliseconds timeout, int attempts) {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.timeouts;
  }
  return fail(ServoError::kTimeout,
              servoName(expect.id) + " did not answer " + commandName(expect.cmd) + " within " +
                  std::to_string(timeout.count()) + " ms (" + attemptsText(attempts) + ")");
}

ServoBusOptions ServoTransactions::options() const {
  std::lock_guard<std::mutex> lock(state_mutex_);
  return options_;
}

void ServoTransactions::retune(const ServoClientTuning& next) {
  std::lock_guard<std::mutex> lock(state_mutex_);
  static_cast<ServoClientTuning&>(options_) = next;
}

ServoStatus ServoTransactions::exchangeLocked(const std::vector<uint8_t>& request,
                                              const Expectation& expect, Packet* answer) {
  const ServoBusOptions options = this->options();  // one transaction, one set of options
  return transact(request, expect, options.timeout, options.retries + 1, answer);
}

bool ServoTransactions::motionWaitCutLocked() const {
  return motion_wait_ &&
         (urgent_ || stops_waiting_ > 0 || (stop_calls_queued_ && stop_calls_queued_()));
}

void ServoTransactions::lockUrgent() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stops_waiting_;
  }
  answer_cv_.notify_all();  // a motion wait gives way
  bus_mutex_.lockUrgent();
  std::lock_guard<std::mutex> lock(state_mutex_);
  --stops_waiting_;
}

void ServoTransactions::stopCallQueued() {
  // Taken and released after the queue changed: a wait that saw no call queued sleeps already.
  { std::lock_guard<std::mutex> lock(state_mutex_); }
  answer_cv_.notify_all();
}

bool ServoTransactions::takeBus(BusPriority priority) {
  switch (priority) {
    case BusPriority::kCaller:
      bus_mutex_.lock();
      return true;
    case BusPriority::kStop:
      lockUrgent();
      return true;
    case BusPriority::kWorker:
      return bus_mutex_.lockUnlessUrgent();
    case BusPriority::kBackground:
      return bus_mutex_.lockBackground();
  }
  return false;
}

ServoStatus ServoTransactions::exchange(const std::vector<uint8_t>& request,
                                        const Expectation& expect, Packet* answer) {
  std::lock_guard<BusMutex> bus(bus_mutex_);
  return exchangeLocked(request, expect, answer);
}

ServoStatus ServoTransactions::sendCommand(const std::vector<uint8_t>& request, Command cmd,
                                           uint8_t id, FrameGate gate,
                                           std::optional<core::MotionGate::Generation> accepted) {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    if (stopping_) return fail(ServoError::kShutdown, "servo bus client is shutting down");
    last_request_ = request;
  }
  if (auto refusal = writeRequest(request, cmd, id, gate, accepted)) return *refusal;
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    ++stats_.commands;
  }
  return ok(std::string(commandName(cmd)) + " sent to " + servoName(id) +
            " (not waiting for completion)");
}

void ServoTransactions::writeStops(const std::vector<uint8_t>& ids, std::vector<bool>* written) {
  written->assign(ids.size(), false);
  lockUrgent();
  std::lock_guard<BusMutex> bus(bus_mutex_, std::adopt_lock);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const std::vector<uint8_t> frame = encodeSpin(ids[i], false, SpinMode::kStop, 0, 0);
    (*written)[i] = sendCommand(frame, Command::kSpin, ids[i], FrameGate::kSafetyAction).ok();
  }
}

void ServoTransactions::requestUrgent() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    urgent_ = true;
  }
  answer_cv_.notify_all();  // a motion wait gives way
  bus_mutex_.requestUrgent();
}

void ServoTransactions::endUrgent() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    urgent_ = false;
  }
  bus_mutex_.endUrgent();
}

}  // namespace serial_robot_driver::devices::servo_bus
