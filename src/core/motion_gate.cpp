#include "serial_robot_driver/core/motion_gate.h"

namespace serial_robot_driver::core {

const char* toString(GateState state) {
  switch (state) {
    case GateState::kOpen:
      return "open";
    case GateState::kLocked:
      return "e_stop engaged";
    case GateState::kClosed:
      return "shutting down";
    case GateState::kVoided:
      return "e-stop engaged after this command was accepted";
  }
  return "?";
}

void MotionGate::setLocked(bool locked) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (locked && !locked_) generation_.fetch_add(1);
  locked_ = locked;
}

void MotionGate::close() {
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
}

GateState MotionGate::stateLocked() const {
  if (closed_) return GateState::kClosed;
  return locked_ ? GateState::kLocked : GateState::kOpen;
}

GateState MotionGate::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stateLocked();
}

GateState MotionGate::writeIfOpen(const std::function<bool()>& write, bool* written,
                                  std::optional<Generation> accepted) {
  std::lock_guard<std::mutex> lock(mutex_);
  GateState state = stateLocked();
  if (state == GateState::kOpen && accepted && *accepted != generation_.load()) {
    state = GateState::kVoided;
  }
  if (state != GateState::kOpen) {
    ++refused_;
    *written = false;
    return state;
  }
  *written = write();
  return state;
}

uint64_t MotionGate::refusedAtWrite() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return refused_;
}

}  // namespace serial_robot_driver::core
