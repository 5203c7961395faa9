// Times as the trajectory messages carry them, ROS-free, for every front end of the executor: a
// stamp's seconds and nanoseconds (the nanoseconds not necessarily normalised: a sender may put
// anything there), its steady start, the stamps an action server can compute with, the longest
// duration a message holds, and how a goal whose handling failed is answered. Computed in
// integers and doubles, never with a middleware's time type, which may throw at its range's ends:
// any stamp gives a finite time, and the executor refuses a start too far ahead.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "serial_robot_driver/trajectory/goal.h"

namespace serial_robot_driver::trajectory {

/// A message's stamp as it came: seconds and nanoseconds, each as sent.
struct MessageStamp {
  int64_t sec = 0;
  int64_t nsec = 0;
  bool isZero() const { return sec == 0 && nsec == 0; }
};

/// `later` - `earlier` in seconds, for any two stamps.
double secondsBetween(const MessageStamp& later, const MessageStamp& earlier);
/// The steady time of a message stamped `stamp` (zero: `steady_now`), given the two clocks read
/// together (`steady_now`, `message_now`).
double steadyStart(const MessageStamp& stamp, double steady_now, const MessageStamp& message_now);

/// Whether an action server can add its timeouts (seconds) to a goal_id `stamp`: nsec normalised
/// and a day of seconds left before the end of the 32-bit seconds.
bool actionTimersCanTake(const MessageStamp& stamp);
/// The warning for a goal or cancel of `server` refused for its goal_id `stamp`.
std::string unusableStampText(const std::string& server, const MessageStamp& stamp);

/// `seconds` as a message's duration (32-bit seconds) can hold it: clamped to [0, 2^31 - 2];
/// NaN gives 0 (a goal may last longer than a message's duration can say).
double messageDuration(double seconds);

/// Where a goal is in its life, as its action server sees it.
enum class GoalPhase {
  kPending,  ///< received, not yet accepted (or recalled before acceptance)
  kActive,   ///< accepted, running (or being preempted)
  kOver,     ///< answered already
};
/// How a goal whose handling ended in the internal error `what` is answered (its client must
/// not wait for ever): rejected while pending, aborted once active, nothing once over.
std::optional<GoalOutcome> internalErrorOutcome(GoalPhase phase, const std::string& what);

}  // namespace serial_robot_driver::trajectory
