#include "serial_robot_driver/trajectory/message_time.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "serial_robot_driver/core/guarded_call.h"

namespace serial_robot_driver::trajectory {

double secondsBetween(const MessageStamp& later, const MessageStamp& earlier) {
  // Each part on its own: a message's nsec is not normalised.
  const int64_t seconds = later.sec - earlier.sec;
  const int64_t nanoseconds = later.nsec - earlier.nsec;
  return static_cast<double>(seconds) + static_cast<double>(nanoseconds) * 1e-9;
}

double steadyStart(const MessageStamp& stamp, double steady_now, const MessageStamp& message_now) {
  if (stamp.isZero()) return steady_now;
  return steady_now + secondsBetween(stamp, message_now);
}

bool actionTimersCanTake(const MessageStamp& stamp) {
  constexpr int64_t kSecondsLeft = 86400;
  constexpr int64_t kLastSecond = std::numeric_limits<uint32_t>::max();
  return stamp.nsec >= 0 && stamp.nsec < 1000000000 && stamp.sec >= 0 &&
         stamp.sec <= kLastSecond - kSecondsLeft;
}

std::string unusableStampText(const std::string& server, const MessageStamp& stamp) {
  return server + ": goal or cancel refused: its goal_id.stamp (" + std::to_string(stamp.sec) +
         " s, " + std::to_string(stamp.nsec) +
         " ns) is not a time the action server can compute with";
}

double messageDuration(double seconds) {
  constexpr double kLongest = std::numeric_limits<int32_t>::max() - 1.0;
  if (std::isnan(seconds)) return 0.0;
  return std::clamp(seconds, 0.0, kLongest);
}

std::optional<GoalOutcome> internalErrorOutcome(GoalPhase phase, const std::string& what) {
  const std::string text = core::internalErrorText(what);
  switch (phase) {
    case GoalPhase::kPending:
      return outcome(GoalStatus::kRejected, result_code::kInvalidGoal, text);
    case GoalPhase::kActive:
      return outcome(GoalStatus::kAborted, result_code::kInvalidGoal, text);
    case GoalPhase::kOver:
      break;
  }
  return std::nullopt;
}

}  // namespace serial_robot_driver::trajectory
