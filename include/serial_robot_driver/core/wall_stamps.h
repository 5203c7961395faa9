// When a core event (a frame's last byte, a loop tick: the steady clock) happened on the wall
// clock, which message stamps use (ROS 1's ros::Time::now() and ROS 2's system clock alike). Every
// front end stamps an event through this one function, so one frame carries one stamp in every
// graph it is published on.
#pragma once

#include <chrono>
#include <memory>

#include "serial_robot_driver/transport/recorded_stream.h"

namespace serial_robot_driver::core {

/// Nanoseconds since the Unix epoch at which `event` happened: `wall_now` minus how long ago it was
/// (`steady_now` - `event`). An event "in the future" (clock read order) is now; the epoch at the
/// earliest.
std::chrono::nanoseconds wallTimeOf(std::chrono::steady_clock::time_point event,
                                    std::chrono::system_clock::time_point wall_now,
                                    std::chrono::steady_clock::time_point steady_now);

/// The stamps of frames from their arrival. Live: wallTimeOf() now, the last conversion remembered
/// per thread, so the users of one arrival on a thread (every front end's message of a frame, the
/// wire capture of its chunk) get the very same stamp. Replaying (`replay_timeline` set): the
/// recorded stamp the arrival stands for on the replay's timeline, exactly.
class WallStamps {
 public:
  explicit WallStamps(std::shared_ptr<const transport::ReplayPacing> replay_timeline = {})
      : replay_timeline_(std::move(replay_timeline)) {}
  std::chrono::nanoseconds operator()(std::chrono::steady_clock::time_point arrival) const;

 private:
  std::shared_ptr<const transport::ReplayPacing> replay_timeline_;
};

}  // namespace serial_robot_driver::core
