#pragma once
// Hostile input for the driver's DDS subscriptions (cmd_vel, cmd_vel_stamped, e_stop,
// joint_commands, joint_trajectory), as a ROS 2 peer could send it: well-formed samples with every
// field at its extremes (NaN, ±Inf, ±1e308, denormals, empty and 100 000-element arrays, mismatched
// lengths, duplicate, unknown, 10 000-character and non-UTF-8 names, junk frame_ids, extreme
// stamps, non-increasing and huge trajectories), and CDR bytes that are no valid sample at all
// (truncated, lengths beyond the payload, sequence lengths of 2^32-1 and of 2^32 / element size).
// Each well-formed sample says whether the core must refuse (and count) it; the others are
// accepted and move nothing from the state the test left the robot in (joints at 0, base stopped).
#include <dds/dds.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace dds_test {

/// One sample written to an input's writer.
struct HostileSample {
  std::string what;  ///< for failure messages
  bool refused;      ///< the core refuses it and counts it under the input's name
  std::function<dds_return_t(dds_entity_t writer)> write;
};

/// geometry_msgs/Twist on cmd_vel. `finite_extremes`: also ±1e308 and the largest doubles in
/// the fields the base obeys, which it clamps and drives with (only under the e-stop).
std::vector<HostileSample> hostileTwists(bool finite_extremes);
/// geometry_msgs/TwistStamped on cmd_vel_stamped (refusals counted under cmd_vel).
std::vector<HostileSample> hostileStampedTwists();
/// sensor_msgs/JointState on joint_commands, for a body whose joints are `joints`, all at 0 rad.
std::vector<HostileSample> hostileJointCommands(const std::vector<std::string>& joints);
/// trajectory_msgs/JointTrajectory on joint_trajectory, for the same joints.
std::vector<HostileSample> hostileTrajectories(const std::vector<std::string>& joints);

/// A trajectory_msgs/JointTrajectory whose one point puts `joints` at NaN: refused.
HostileSample nanTrajectory(const std::vector<std::string>& joints);

/// CDR payloads that are no valid sample of the input's type, then one last, well-formed payload
/// that the core refuses and counts (`counted_last`): once it is counted, every payload before it
/// from the same writer has arrived (reliable, in order) and was dropped. The first 4 bytes of
/// every payload are its remaining length (rawWriter()'s sequence<octet>), the rest is written
/// here by hand from the CDR rules. Cyclone pads a payload to a multiple of 4 on the wire, so the
/// truncated ones are short by 4 bytes or more (1 to 3 would arrive as a whole, zero-padded
/// sample).
struct MalformedInput {
  const char* topic;     ///< "rt/cmd_vel", ...
  const char* dds_type;  ///< the type name the driver's reader has
  const char* counted;   ///< the refusal count the last payload adds to ("" when none)
  std::vector<std::vector<uint8_t>> payloads;  ///< the bytes after the leading length
};
std::vector<MalformedInput> malformedInputs();

/// Writes `bytes` as a sequence<octet> sample on a rawWriter().
dds_return_t writeRaw(dds_entity_t writer, const std::vector<uint8_t>& bytes);

}  // namespace dds_test
