#include "hostile_dds_inputs.h"

#include <cstring>
#include <limits>
#include <utility>

#include "serial_robot_driver/dds/messages.h"

namespace dds_test {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDenormal = std::numeric_limits<double>::denorm_min();
constexpr double kMax = std::numeric_limits<double>::max();
constexpr int32_t kIntMin = std::numeric_limits<int32_t>::min();
constexpr int32_t kIntMax = std::numeric_limits<int32_t>::max();
constexpr uint32_t kUintMax = std::numeric_limits<uint32_t>::max();
constexpr std::size_t kHuge = 100000;  // elements: bounded, not gigabytes
const std::string kLong(10000, 'x');
const std::string kNotUtf8 = "\xff\xfe\xc0\x80 joint";

/// A std_msgs/Header's fields; the sample points into these while it is written.
struct HeaderSpec {
  int32_t sec = 0;
  uint32_t nanosec = 0;
  std::string frame_id;
};

/// A sequence<string> pointing into `texts` (which must outlive it).
struct StringSeq {
  explicit StringSeq(const std::vector<std::string>& texts) {
    for (const std::string& text : texts) pointers.push_back(const_cast<char*>(text.c_str()));
  }
  dds_sequence_string seq() {
    const auto n = static_cast<uint32_t>(pointers.size());
    return {n, n, pointers.data(), false};
  }
  std::vector<char*> pointers;
};

dds_sequence_double seqOf(std::vector<double>& values) {
  const auto n = static_cast<uint32_t>(values.size());
  return {n, n, values.data(), false};
}

void setHeader(std_msgs_msg_dds__Header_& header, const HeaderSpec& spec) {
  header.stamp.sec = spec.sec;
  header.stamp.nanosec = spec.nanosec;
  header.frame_id = const_cast<char*>(spec.frame_id.c_str());
}

/// The header extremes: junk frame_ids and stamps no clock has (negative, huge, nanosec >= 1e9).
std::vector<HeaderSpec> hostileHeaders() {
  return {{kIntMin, 0, ""},
          {kIntMax, kUintMax, kLong},
          {-1, 1000000000, kNotUtf8},
          {0, kUintMax, "\x01\x02"},
          {kIntMax, 999999999, "odom"}};
}

HostileSample twist(const std::string& what, bool refused, std::vector<double> fields) {
  return {what, refused, [fields](dds_entity_t writer) {
            geometry_msgs_msg_dds__Twist_ msg{{fields[0], fields[1], fields[2]},
                                              {fields[3], fields[4], fields[5]}};
            return dds_write(writer, &msg);
          }};
}

/// A sample of Msg from `spec`: its header and its names (the field `names`) set here, the rest
/// by `write_rest(msg, spec, writer)`, which writes it.
template <typename Msg, typename Spec, typename WriteRest>
HostileSample named(const std::string& what, bool refused, Spec spec,
                    dds_sequence_string Msg::*names, WriteRest write_rest) {
  return {what, refused, [spec, names, write_rest](dds_entity_t writer) mutable {
            Msg msg{};
            setHeader(msg.header, spec.header);
            StringSeq strings(spec.names);
            msg.*names = strings.seq();
            return write_rest(msg, spec, writer);
          }};
}

struct JointStateSpec {
  HeaderSpec header;
  std::vector<std::string> names;
  std::vector<double> position, velocity, effort;
};

HostileSample jointState(const std::string& what, bool refused, JointStateSpec spec) {
  using Msg = sensor_msgs_msg_dds__JointState_;
  return named(what, refused, std::move(spec), &Msg::name,
               [](Msg& msg, JointStateSpec& spec, dds_entity_t writer) {
                 msg.position = seqOf(spec.position);
                 msg.velocity = seqOf(spec.velocity);
                 msg.effort = seqOf(spec.effort);
                 return dds_write(writer, &msg);
               });
}

struct PointSpec {
  std::vector<double> positions, velocities, accelerations, effort;
  int32_t sec = 1;
  uint32_t nanosec = 0;
};

struct TrajectorySpec {
  HeaderSpec header;
  std::vector<std::string> names;
  std::vector<PointSpec> points;
};

HostileSample trajectory(const std::string& what, bool refused, TrajectorySpec spec) {
  using Msg = trajectory_msgs_msg_dds__JointTrajectory_;
  return named(what, refused, std::move(spec), &Msg::joint_names,
               [](Msg& msg, TrajectorySpec& spec, dds_entity_t writer) {
                 std::vector<trajectory_msgs_msg_dds__JointTrajectoryPoint_> points;
                 for (PointSpec& point : spec.points) {
                   points.push_back({seqOf(point.positions),
                                     seqOf(point.velocities),
                                     seqOf(point.accelerations),
                                     seqOf(point.effort),
                                     {point.sec, point.nanosec}});
                 }
                 const auto n = static_cast<uint32_t>(points.size());
                 msg.points = {n, n, points.data(), false};
                 return dds_write(writer, &msg);
               });
}

/// Little-endian CDR written by hand after a payload's leading 4-byte length: `at` counts from
/// the payload's start, as CDR aligns.
class Cdr {
 public:
  Cdr& u32(uint32_t value) {
    align(4);
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<uint8_t>(value >> (8 * i)));
    return *this;
  }
  Cdr& f64(double value) {
    align(8);
    uint64_t bits = 0;
    std::memcpy(&bits, &value, 8);
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<uint8_t>(bits >> (8 * i)));
    return *this;
  }
  /// A CDR string: its length with the NUL, the characters, the NUL.
  Cdr& str(const std::string& text) {
    u32(static_cast<uint32_t>(text.size() + 1));
    bytes_.insert(bytes_.end(), text.begin(), text.end());
    bytes_.push_back(0);
    return *this;
  }
  Cdr& raw(std::vector<uint8_t> more) {
    bytes_.insert(bytes_.end(), more.begin(), more.end());
    return *this;
  }
  std::vector<uint8_t> bytes() const { return bytes_; }

 private:
  void align(std::size_t n) {
    while ((4 + bytes_.size()) % n != 0) bytes_.push_back(0);
  }
  std::vector<uint8_t> bytes_;
};

/// A header after the leading length (which stands for header.stamp.sec).
Cdr header(const std::string& frame_id) { return std::move(Cdr().u32(0).str(frame_id)); }

}  // namespace

std::vector<HostileSample> hostileTwists(bool finite_extremes) {
  std::vector<HostileSample> samples;
  if (finite_extremes) {
    for (double value : {1e308, -1e308, kMax, -kMax}) {
      samples.push_back(twist("linear.x " + std::to_string(value), false, {value, 0, 0, 0, 0, 0}));
      samples.push_back(twist("angular.z " + std::to_string(value), false, {0, 0, 0, 0, 0, value}));
    }
    return samples;
  }
  for (double value : {kNaN, kInf, -kInf}) {
    const std::string text = std::to_string(value);
    samples.push_back(twist("linear.x " + text, true, {value, 0, 0, 0, 0, 0}));
    samples.push_back(twist("angular.z " + text, true, {0, 0, 0, 0, 0, value}));
  }
  samples.push_back(twist("every field NaN", true, std::vector<double>(6, kNaN)));
  // The fields a differential base does not use are not looked at, as on the ROS 1 side.
  samples.push_back(twist("unused fields NaN", false, {0, kNaN, kInf, -kInf, 1e308, 0}));
  samples.push_back(twist("denormals", false, std::vector<double>(6, kDenormal)));
  return samples;
}

std::vector<HostileSample> hostileStampedTwists() {
  std::vector<HostileSample> samples;
  for (const HeaderSpec& spec : hostileHeaders()) {
    for (bool refused : {true, false}) {
      samples.push_back({"header " + std::to_string(spec.sec) + (refused ? ", NaN" : ", zero"),
                         refused, [spec, refused](dds_entity_t writer) {
                           geometry_msgs_msg_dds__TwistStamped_ msg{};
                           setHeader(msg.header, spec);
                           msg.twist.linear.x = refused ? kNaN : 0.0;
                           msg.twist.angular.z = refused ? -kInf : kDenormal;
                           return dds_write(writer, &msg);
                         }});
    }
  }
  return samples;
}

std::vector<HostileSample> hostileJointCommands(const std::vector<std::string>& joints) {
  const std::string& joint = joints.at(0);
  std::vector<HostileSample> samples;
  for (double value : {kNaN, kInf, -kInf, 1e308, -1e308, kMax}) {
    samples.push_back(
        jointState("position " + std::to_string(value), true, {{}, {joint}, {value}, {}, {}}));
  }
  samples.push_back(jointState("denormal", false, {{}, {joint}, {kDenormal}, {}, {}}));
  samples.push_back(jointState("empty", true, {}));
  samples.push_back(jointState("more names than positions", true, {{}, joints, {0.0}, {}, {}}));
  samples.push_back(jointState("a position, no name", true, {{}, {}, {0.0}, {}, {}}));
  samples.push_back(jointState("duplicate", true, {{}, {joint, joint}, {0.0, 0.0}, {}, {}}));
  for (const std::string& name : {std::string(), std::string("no_such_joint"), kLong, kNotUtf8}) {
    samples.push_back(
        jointState("unknown '" + name.substr(0, 20) + "'", true, {{}, {name}, {0.0}, {}, {}}));
  }
  samples.push_back(jointState(
      "100000 names", true,
      {{}, std::vector<std::string>(kHuge, joint), std::vector<double>(kHuge, 0.0), {}, {}}));
  samples.push_back(jointState("100000 unknown names, no positions", true,
                               {{}, std::vector<std::string>(kHuge, "j"), {}, {}, {}}));
  // What the body does not read (header, velocity, effort) does not make a command bad.
  for (const HeaderSpec& spec : hostileHeaders()) {
    samples.push_back(
        jointState("header " + std::to_string(spec.sec), false,
                   {spec, {joint}, {0.0}, {kNaN, kInf}, std::vector<double>(kHuge, kNaN)}));
  }
  return samples;
}

std::vector<HostileSample> hostileTrajectories(const std::vector<std::string>& joints) {
  const std::vector<double> zeros(joints.size(), 0.0);
  const PointSpec still{zeros, {}, {}, {}, 1, 0};
  std::vector<HostileSample> samples;
  for (double value : {kNaN, kInf, -1e308, kMax, kDenormal * -1e300}) {
    PointSpec point = still;
    point.positions.back() = value;
    const bool finite_in_reach = value > -1.0 && value < 1.0;
    samples.push_back(
        trajectory("position " + std::to_string(value), !finite_in_reach, {{}, joints, {point}}));
  }
  PointSpec nan_velocity = still;
  nan_velocity.velocities.assign(joints.size(), kNaN);
  samples.push_back(trajectory("velocity NaN", true, {{}, joints, {nan_velocity}}));
  samples.push_back(trajectory("no joints", true, {{}, {}, {still}}));
  samples.push_back(trajectory("duplicate joint", true, {{}, {joints[0], joints[0]}, {still}}));
  const PointSpec one_position{{0.0}, {}, {}, {}, 1, 0};
  samples.push_back(trajectory("unknown joint", true, {{}, {kNotUtf8}, {one_position}}));
  samples.push_back(trajectory("a point short of positions", true, {{}, joints, {one_position}}));
  PointSpec later = still, earlier = still;
  later.sec = 2;
  samples.push_back(trajectory("times going back", true, {{}, joints, {later, earlier}}));
  samples.push_back(trajectory("two points at one time", true, {{}, joints, {still, still}}));
  PointSpec negative = still;
  negative.sec = kIntMin;
  samples.push_back(trajectory("negative time_from_start", true, {{}, joints, {negative}}));
  PointSpec unnormalised = still;
  unnormalised.nanosec = kUintMax;
  samples.push_back(trajectory("nanosec 2^32-1", false, {{}, joints, {unnormalised}}));
  // Stamps no clock has: far past, far ahead, nanosec beyond a second.
  for (const HeaderSpec& spec : {HeaderSpec{kIntMin, 0, ""}, HeaderSpec{kIntMax, 0, kLong},
                                 HeaderSpec{-1, kUintMax, kNotUtf8}}) {
    samples.push_back(
        trajectory("stamp " + std::to_string(spec.sec), true, {spec, joints, {still}}));
  }
  std::vector<PointSpec> many(kHuge, still);
  for (std::size_t i = 0; i < many.size(); ++i) many[i].sec = static_cast<int32_t>(i + 1);
  many.back().positions.back() = kNaN;
  samples.push_back(trajectory("100000 points, the last NaN", true, {{}, joints, many}));
  return samples;
}

HostileSample nanTrajectory(const std::vector<std::string>& joints) {
  const PointSpec point{std::vector<double>(joints.size(), kNaN), {}, {}, {}, 1, 0};
  return trajectory("every position NaN", true, {{}, joints, {point}});
}

std::vector<MalformedInput> malformedInputs() {
  const uint32_t k2To32Over8 = 0x20000000;                    // times 8 bytes: 2^32, 0 in 32 bits
  std::vector<uint8_t> nan_linear_x{0x00, 0x00, 0xf8, 0x7f};  // the high half of a NaN double
  nan_linear_x.resize(44, 0);
  return {
      {"rt/cmd_vel",
       "geometry_msgs::msg::dds_::Twist_",
       "cmd_vel",
       {{}, std::vector<uint8_t>(20, 0xff), std::vector<uint8_t>(40, 0), nan_linear_x}},
      {"rt/cmd_vel_stamped",
       "geometry_msgs::msg::dds_::TwistStamped_",
       "cmd_vel",
       {Cdr().u32(0).u32(kUintMax).bytes(), Cdr().u32(0).u32(64).raw({'a', 'b'}).bytes(),
        Cdr().u32(0).u32(3).raw({'a', 'b', 'c'}).bytes(), Cdr().u32(0).u32(0).bytes(),
        header("base_link").bytes(),
        header("").f64(kNaN).f64(0).f64(0).f64(0).f64(0).f64(0).bytes()}},
      // A Bool of 2 (the leading length's low byte): no bool; taken, it would engage the e-stop.
      {"rt/e_stop", "std_msgs::msg::dds_::Bool_", "", {{0x00, 0x00}}},
      {"rt/joint_commands",
       "sensor_msgs::msg::dds_::JointState_",
       "joint_commands",
       {header("").u32(kUintMax).bytes(), header("").u32(1).u32(0x7fffffff).bytes(),
        header("").u32(0).u32(k2To32Over8).f64(0.0).bytes(),
        header("").u32(0).u32(kUintMax).bytes(),
        header("").u32(1).str("no_such_joint").u32(1).f64(0.0).u32(0).u32(0).bytes()}},
      {"rt/joint_trajectory",
       "trajectory_msgs::msg::dds_::JointTrajectory_",
       "joint_trajectory",
       {header("").u32(kUintMax).bytes(), header("").u32(0).u32(kUintMax).bytes(),
        header("").u32(0).u32(0x10000000).bytes(),
        header("").u32(0).u32(1).u32(k2To32Over8).f64(0.0).bytes(),
        header("").u32(1).str("no_such_joint").u32(0).bytes()}},
  };
}

dds_return_t writeRaw(dds_entity_t writer, const std::vector<uint8_t>& bytes) {
  struct {
    uint32_t maximum, length;
    const uint8_t* buffer;
    bool release;
  } sample{static_cast<uint32_t>(bytes.size()), static_cast<uint32_t>(bytes.size()), bytes.data(),
           false};
  return dds_write(writer, &sample);
}

}  // namespace dds_test
