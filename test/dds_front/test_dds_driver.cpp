// dds_driver against robot_sim (in this process, on a pty), seen from a second DDS participant the
// way a ROS 2 machine sees it (ros2_peer.h: plain Cyclone, the test's own domain, unicast peer
// 127.0.0.1): every topic with its type name, ROS 2's own type hash and QoS; joint_states that
// follow joint_commands; cmd_vel driving the base (wheel frames the simulated base applies), the
// deadman and e_stop stopping it; the node in ros_discovery_info and its diagnostics; hostile
// samples and malformed CDR on every input (hostile_dds_inputs.h) refused, counted, moving nothing,
// the driver going on; SIGTERM ending it with the base's last zero-speed frame. Waits for
// conditions; no timing is asserted.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../dds/published_type_hashes.h"
#include "hostile_dds_inputs.h"
#include "ros2_peer.h"
#include "serial_robot_driver/dds/messages.h"
#include "serial_robot_driver/devices/base/sim/base_sim.h"
#include "serial_robot_driver/devices/body/sim/body_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/process_support.h"

namespace {

namespace sim = serial_robot_driver::sim;
using dds_test::waitFor;
using serial_robot_driver::devices::base::sim::baseStats;
using serial_robot_driver::devices::body::sim::bodyStats;

std::string hashOf(const std::string& ros_type) {
  for (const auto& published : dds_test::kPublishedHashes) {
    if (ros_type == published.type_name) return std::string("typehash=") + published.hash + ";";
  }
  return "(no published hash for " + ros_type + ")";
}

// The suite's robot_sim, dds_driver and peer (set up once: DdsDriver::SetUpTestSuite).
std::string link_, config_;
int domain_ = 0;
std::unique_ptr<sim::RobotSim> robot_;
std::unique_ptr<test_support::ChildProcess> driver_;
std::unique_ptr<dds_test::Ros2Peer> peer_;

sim::SimStats robot_stats() { return robot_->stats(); }

/// robot_sim's three devices on one pty and dds_driver on it, for the whole suite.
class DdsDriver : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string id = std::to_string(getpid());
    link_ = "/tmp/srd_test_dds_driver_" + id;
    config_ = link_ + ".yaml";
    domain_ = dds_test::privateDomainId(120, 50);
    test_support::removeStaleLink(link_);
    sim::SimOptions options;
    options.link = link_;
    robot_ = std::make_unique<sim::RobotSim>(options);
    robot_->start();
    std::ofstream(config_) << "port: " << link_ << "\nservo_bus: {state_ids: [1]}\n"
                           << "base: {cmd_vel_timeout: 0.5}\n"
                           << "ros2: {domain_id: " << domain_ << ", peers: [127.0.0.1]}\n";
    driver_ = std::make_unique<test_support::ChildProcess>(
        SRD_DDS_DRIVER, std::vector<std::string>{"--config", config_});
    peer_ = std::make_unique<dds_test::Ros2Peer>(domain_);
  }

  static void TearDownTestSuite() {
    peer_.reset();
    if (driver_ && driver_->running()) driver_->signal(SIGTERM);
    if (driver_) driver_->waitExit(30.0);
    driver_.reset();
    robot_->stop();
    robot_.reset();
    std::remove(config_.c_str());
  }

  void TearDown() override {
    if (HasFailure() && driver_) std::cerr << "dds_driver's output:\n" << driver_->output();
  }
};

struct ExpectedTopic {
  bool publication;
  const char* topic;
  const char* ros_type;
  int32_t depth;
};

TEST_F(DdsDriver, EveryTopicHasRos2sNameTypeHashAndQos) {
  const ExpectedTopic expected[] = {
      {true, "rt/joint_states", "sensor_msgs/msg/JointState", 10},
      {true, "rt/imu/data", "sensor_msgs/msg/Imu", 10},
      {true, "rt/odom", "nav_msgs/msg/Odometry", 10},
      {true, "rt/tf", "tf2_msgs/msg/TFMessage", 100},
      {true, "rt/battery", "sensor_msgs/msg/BatteryState", 10},
      {true, "rt/wheel_states", "sensor_msgs/msg/JointState", 10},
      {true, "rt/diagnostics", "diagnostic_msgs/msg/DiagnosticArray", 10},
      {true, "rt/servo_states", "sensor_msgs/msg/JointState", 10},
      {false, "rt/cmd_vel", "geometry_msgs/msg/Twist", 10},
      {false, "rt/cmd_vel_stamped", "geometry_msgs/msg/TwistStamped", 10},
      {false, "rt/e_stop", "std_msgs/msg/Bool", 10},
      {false, "rt/joint_commands", "sensor_msgs/msg/JointState", 10},
      {false, "rt/joint_trajectory", "trajectory_msgs/msg/JointTrajectory", 10},
  };
  for (const ExpectedTopic& topic : expected) {
    SCOPED_TRACE(topic.topic);
    const auto seen = peer_->discover(topic.publication, topic.topic);
    ASSERT_TRUE(seen);
    std::string dds_type = topic.ros_type;  // pkg/msg/Type -> pkg::msg::dds_::Type_
    dds_type.replace(dds_type.find("/msg/"), 5, "::msg::dds_::");
    EXPECT_EQ(seen->type_name, dds_type + "_");
    EXPECT_EQ(seen->user_data, hashOf(topic.ros_type));
    EXPECT_EQ(seen->reliability, DDS_RELIABILITY_RELIABLE);
    EXPECT_EQ(seen->durability, DDS_DURABILITY_VOLATILE);
    EXPECT_EQ(seen->history, DDS_HISTORY_KEEP_LAST);
    EXPECT_EQ(seen->depth, topic.depth);
  }
}

TEST_F(DdsDriver, JointStatesFollowJointCommands) {
  const dds_entity_t states =
      peer_->reader(sensor_msgs_msg_dds__JointState__desc, "rt/joint_states");
  const dds_entity_t commands =
      peer_->writer(sensor_msgs_msg_dds__JointState__desc, "rt/joint_commands");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(commands); }));
  char joint_1[] = "joint_1";
  char* names[] = {joint_1};
  double positions[] = {0.5};
  sensor_msgs_msg_dds__JointState_ command{};
  char empty[] = "";
  command.header.frame_id = empty;
  command.name = {1, 1, names, false};
  command.position = {1, 1, positions, false};
  ASSERT_EQ(dds_write(commands, &command), DDS_RETCODE_OK);
  // 0.5 rad on a 4096-tick turn around tick 2048: 2048 + 326 (0.5 * 4096 / 2 pi = 325.95).
  ASSERT_TRUE(waitFor([] { return bodyStats(robot_stats()).servos.at(0).target == 2374; }));
  const double reached = (2374 - 2048) * 2 * M_PI / 4096;
  EXPECT_TRUE(
      dds_test::waitForSample<sensor_msgs_msg_dds__JointState_>(states, [&](const auto& state) {
        return state.name._length == 2 && std::strcmp(state.name._buffer[0], "joint_1") == 0 &&
               std::strcmp(state.name._buffer[1], "joint_2") == 0 && state.position._length == 2 &&
               std::abs(state.position._buffer[0] - reached) < 1e-9 &&
               std::abs(state.position._buffer[1]) < 1e-9 && state.header.stamp.sec > 1700000000;
      }));
}

TEST_F(DdsDriver, ServoStatesCarryThePolledBusServo) {
  const dds_entity_t states =
      peer_->reader(sensor_msgs_msg_dds__JointState__desc, "rt/servo_states");
  EXPECT_TRUE(dds_test::waitForSample<sensor_msgs_msg_dds__JointState_>(states, [](const auto& s) {
    return s.name._length == 1 && std::strcmp(s.name._buffer[0], "servo_1") == 0 &&
           s.position._length == 1 && std::isfinite(s.position._buffer[0]) &&
           s.header.stamp.sec > 1700000000;
  }));
}

TEST_F(DdsDriver, JointTrajectoryMovesTheBodysJoints) {
  const dds_entity_t trajectories =
      peer_->writer(trajectory_msgs_msg_dds__JointTrajectory__desc, "rt/joint_trajectory");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(trajectories); }));
  char joint_1[] = "joint_1", joint_2[] = "joint_2", empty[] = "";
  char* names[] = {joint_1, joint_2};
  double positions[] = {0.3, -0.2};
  trajectory_msgs_msg_dds__JointTrajectoryPoint_ point{};
  point.positions = {2, 2, positions, false};
  point.time_from_start.sec = 1;
  trajectory_msgs_msg_dds__JointTrajectory_ msg{};  // stamp zero: now
  msg.header.frame_id = empty;
  msg.joint_names = {2, 2, names, false};
  msg.points = {1, 1, &point, false};
  ASSERT_EQ(dds_write(trajectories, &msg), DDS_RETCODE_OK);
  // 0.3 rad and -0.2 rad on 4096-tick turns around 2048: 2048 + 196 (195.6), 2048 - 130 (130.4).
  EXPECT_TRUE(waitFor([] {
    const auto servos = bodyStats(robot_stats()).servos;
    return servos.size() == 2 && servos[0].target == 2244 && servos[1].target == 1918;
  }));
}

/// Waits until the simulated base has applied `frames` more speed frames and each of them left
/// its wheels at `speed` (ticks per period): what reached the wire, not what the node says.
bool baseHoldsSpeed(bool moving, uint64_t frames = 25) {
  uint64_t since = 0;
  bool held = false;
  return waitFor([&] {
    const auto stats = baseStats(robot_stats());
    const bool now_moving = stats.last_left_speed != 0 && stats.last_right_speed != 0;
    if (now_moving != moving) {
      held = false;
      return false;
    }
    if (!held) since = stats.speed_frames_applied;
    held = true;
    return stats.speed_frames_applied >= since + frames;
  });
}

TEST_F(DdsDriver, CmdVelDrivesTheBaseTheDeadmanAndEStopStopIt) {
  const dds_entity_t cmd_vel = peer_->writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  const dds_entity_t e_stop = peer_->writer(std_msgs_msg_dds__Bool__desc, "rt/e_stop");
  ASSERT_TRUE(waitFor(
      [&] { return dds_test::Ros2Peer::matched(cmd_vel) && dds_test::Ros2Peer::matched(e_stop); }));
  {
    const dds_test::TwistStream driving(cmd_vel, 0.2);
    EXPECT_TRUE(baseHoldsSpeed(true));
    ASSERT_TRUE(dds_test::writeBool(e_stop, true));
    EXPECT_TRUE(baseHoldsSpeed(false)) << "cmd_vel still flows: only the e-stop stops the base";
    ASSERT_TRUE(dds_test::writeBool(e_stop, false));
    EXPECT_TRUE(baseHoldsSpeed(true)) << "released: the next cmd_vel is obeyed";
  }
  EXPECT_TRUE(baseHoldsSpeed(false)) << "cmd_vel stopped: the deadman stops the base";
}

TEST_F(DdsDriver, CmdVelStampedDrivesTheBaseToo) {
  const dds_entity_t stamped =
      peer_->writer(geometry_msgs_msg_dds__TwistStamped__desc, "rt/cmd_vel_stamped");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(stamped); }));
  char frame[] = "base_link";
  geometry_msgs_msg_dds__TwistStamped_ msg{};
  msg.header.frame_id = frame;
  msg.twist.linear.x = -0.2;
  // Written on every check, as a teleop node streams it, until a frame moves the wheels backward.
  EXPECT_TRUE(waitFor([&] {
    dds_write(stamped, &msg);
    const auto stats = baseStats(robot_stats());
    return stats.last_left_speed < 0 && stats.last_right_speed < 0;
  }));
  EXPECT_TRUE(baseHoldsSpeed(false)) << "stopped writing: the deadman stops the base";
}

TEST_F(DdsDriver, TheNodeIsInRosDiscoveryInfoWithItsEndpoints) {
  const auto joint_states = peer_->discover(true, "rt/joint_states");
  const auto cmd_vel = peer_->discover(false, "rt/cmd_vel");
  ASSERT_TRUE(joint_states && cmd_vel);
  const dds_entity_t reader = peer_->reader(rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                            "ros_discovery_info", DDS_DURABILITY_TRANSIENT_LOCAL);
  const auto has = [](const rmw_dds_common_msg_dds__Gid_* gids, uint32_t count,
                      const dds_guid_t& guid) {
    for (uint32_t i = 0; i < count; ++i) {
      if (std::memcmp(gids[i].data, guid.v, 16) == 0) return true;
    }
    return false;
  };
  EXPECT_TRUE(dds_test::waitForSample<rmw_dds_common_msg_dds__ParticipantEntitiesInfo_>(
      reader, [&](const auto& info) {
        if (std::memcmp(info.gid.data, joint_states->participant.v, 16) != 0) return false;
        for (uint32_t i = 0; i < info.node_entities_info_seq._length; ++i) {
          const auto& node = info.node_entities_info_seq._buffer[i];
          if (std::string(node.node_name) == "driver_node" &&
              std::string(node.node_namespace) == "/" &&
              has(node.writer_gid_seq._buffer, node.writer_gid_seq._length, joint_states->guid) &&
              has(node.reader_gid_seq._buffer, node.reader_gid_seq._length, cmd_vel->guid)) {
            return true;
          }
        }
        return false;
      }));
}

TEST_F(DdsDriver, DiagnosticsCarryTheNodesStatuses) {
  const dds_entity_t reader =
      peer_->reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics");
  const auto named = [](const diagnostic_msgs_msg_dds__DiagnosticArray_& array,
                        const std::string& name) {
    for (uint32_t i = 0; i < array.status._length; ++i) {
      if (name == array.status._buffer[i].name) return true;
    }
    return false;
  };
  EXPECT_TRUE(dds_test::waitForSample<diagnostic_msgs_msg_dds__DiagnosticArray_>(
      reader, [&](const auto& array) {
        return named(array, "driver_node: base") && named(array, "driver_node: body") &&
               named(array, "driver_node: e_stop") && named(array, "driver_node: port " + link_);
      }));
}

/// Whether `array` has the status `name` with the value `key` at `value` or more.
bool counts(const diagnostic_msgs_msg_dds__DiagnosticArray_& array, const std::string& name,
            const std::string& key, int value) {
  for (uint32_t i = 0; i < array.status._length; ++i) {
    const auto& status = array.status._buffer[i];
    for (uint32_t j = 0; name == status.name && j < status.values._length; ++j) {
      if (key == status.values._buffer[j].key &&
          std::stoi(status.values._buffer[j].value) >= value) {
        return true;
      }
    }
  }
  return false;
}

TEST_F(DdsDriver, BadInputIsRefusedAndCountedByTheCoreAsFromRos1) {
  const dds_entity_t cmd_vel = peer_->writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  const dds_entity_t trajectories =
      peer_->writer(trajectory_msgs_msg_dds__JointTrajectory__desc, "rt/joint_trajectory");
  const dds_entity_t diagnostics =
      peer_->reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics");
  ASSERT_TRUE(waitFor([&] {
    return dds_test::Ros2Peer::matched(cmd_vel) && dds_test::Ros2Peer::matched(trajectories);
  }));
  geometry_msgs_msg_dds__Twist_ twist{};
  twist.linear.x = std::nan("");
  ASSERT_EQ(dds_write(cmd_vel, &twist), DDS_RETCODE_OK);
  char joint_1[] = "joint_1", empty[] = "";
  char* names[] = {joint_1};
  double positions[] = {std::nan("")};
  trajectory_msgs_msg_dds__JointTrajectoryPoint_ point{};
  point.positions = {1, 1, positions, false};
  point.time_from_start.sec = 1;
  trajectory_msgs_msg_dds__JointTrajectory_ trajectory{};
  trajectory.header.frame_id = empty;
  trajectory.joint_names = {1, 1, names, false};
  trajectory.points = {1, 1, &point, false};
  ASSERT_EQ(dds_write(trajectories, &trajectory), DDS_RETCODE_OK);
  EXPECT_TRUE(dds_test::waitForSample<diagnostic_msgs_msg_dds__DiagnosticArray_>(
      diagnostics, [](const auto& array) {
        return counts(array, "driver_node: e_stop", "inputs refused: cmd_vel", 1) &&
               counts(array, "driver_node: e_stop", "inputs refused: joint_trajectory", 1);
      }));
  EXPECT_TRUE(baseHoldsSpeed(false)) << "a NaN cmd_vel commands zero speed";
}

/// What the simulated devices hold: the base's encoder ticks and the body's servo targets.
struct AtRest {
  int64_t left = 0, right = 0;
  std::vector<uint16_t> targets;
  bool operator==(const AtRest& other) const {
    return left == other.left && right == other.right && targets == other.targets;
  }
};

AtRest atRest() {
  const auto base = baseStats(robot_stats());
  AtRest rest{base.left_ticks, base.right_ticks, {}};
  for (const auto& servo : bodyStats(robot_stats()).servos) rest.targets.push_back(servo.target);
  return rest;
}

/// The base stopped and both joints commanded to 0 rad (tick 2048): what the hostile samples must
/// leave as it is.
AtRest bringToRest() {
  const dds_entity_t commands =
      peer_->writer(sensor_msgs_msg_dds__JointState__desc, "rt/joint_commands");
  EXPECT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(commands); }));
  char joint_1[] = "joint_1", joint_2[] = "joint_2", empty[] = "";
  char* names[] = {joint_1, joint_2};
  double zeros[] = {0.0, 0.0};
  sensor_msgs_msg_dds__JointState_ command{};
  command.header.frame_id = empty;
  command.name = {2, 2, names, false};
  command.position = {2, 2, zeros, false};
  EXPECT_EQ(dds_write(commands, &command), DDS_RETCODE_OK);
  EXPECT_TRUE(waitFor([] {
    const auto servos = bodyStats(robot_stats()).servos;
    return servos.size() == 2 && servos[0].target == 2048 && servos[1].target == 2048;
  }));
  EXPECT_TRUE(baseHoldsSpeed(false));
  return atRest();
}

/// Writes `samples` in batches that the driver's reader (keep-last 10) holds whole, waiting after
/// each until the core counted under `key` exactly those it must refuse; nothing may move.
void expectRefused(dds_entity_t writer, const std::vector<dds_test::HostileSample>& samples,
                   const std::string& key, dds_test::EStopStatus& status, const AtRest& rest) {
  constexpr std::size_t kBatch = 8;
  uint64_t expected = status.count(key);
  for (std::size_t first = 0; first < samples.size(); first += kBatch) {
    std::string batch;
    for (std::size_t i = first; i < std::min(first + kBatch, samples.size()); ++i) {
      ASSERT_EQ(samples[i].write(writer), DDS_RETCODE_OK) << samples[i].what;
      expected += samples[i].refused ? 1 : 0;
      batch += samples[i].what + "; ";
    }
    EXPECT_TRUE(status.waitForCount(key, expected))
        << key << " after " << batch << ": " << status.count(key) << " != " << expected;
    EXPECT_TRUE(atRest() == rest) << "moved by one of " << batch;
    ASSERT_TRUE(driver_->running()) << batch;
  }
}

const std::vector<std::string> kJoints{"joint_1", "joint_2"};

/// A valid cmd_vel still drives the base, and stopping it stops it: the driver goes on.
void expectTheBaseStillDrives() {
  const dds_entity_t cmd_vel = peer_->writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(cmd_vel); }));
  {
    const dds_test::TwistStream driving(cmd_vel, 0.2);
    EXPECT_TRUE(baseHoldsSpeed(true)) << "a valid cmd_vel after the hostile ones drives the base";
  }
  EXPECT_TRUE(baseHoldsSpeed(false));
}

TEST_F(DdsDriver, HostileSamplesOnEveryInputAreRefusedMoveNothingAndTheDriverGoesOn) {
  dds_test::EStopStatus status(*peer_);
  const AtRest rest = bringToRest();
  const dds_entity_t cmd_vel = peer_->writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  const dds_entity_t stamped =
      peer_->writer(geometry_msgs_msg_dds__TwistStamped__desc, "rt/cmd_vel_stamped");
  const dds_entity_t commands =
      peer_->writer(sensor_msgs_msg_dds__JointState__desc, "rt/joint_commands");
  const dds_entity_t trajectories =
      peer_->writer(trajectory_msgs_msg_dds__JointTrajectory__desc, "rt/joint_trajectory");
  ASSERT_TRUE(waitFor([&] {
    for (dds_entity_t writer : {cmd_vel, stamped, commands, trajectories}) {
      if (!dds_test::Ros2Peer::matched(writer)) return false;
    }
    return true;
  }));
  expectRefused(cmd_vel, dds_test::hostileTwists(false), "inputs refused: cmd_vel", status, rest);
  expectRefused(stamped, dds_test::hostileStampedTwists(), "inputs refused: cmd_vel", status, rest);
  expectRefused(commands, dds_test::hostileJointCommands(kJoints), "inputs refused: joint_commands",
                status, rest);
  expectRefused(trajectories, dds_test::hostileTrajectories(kJoints),
                "inputs refused: joint_trajectory", status, rest);
  expectTheBaseStillDrives();
}

TEST_F(DdsDriver, FiniteExtremesUnderTheEStopMoveNothing) {
  dds_test::EStopStatus status(*peer_);
  const AtRest rest = bringToRest();
  const dds_entity_t cmd_vel = peer_->writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  const dds_entity_t e_stop = peer_->writer(std_msgs_msg_dds__Bool__desc, "rt/e_stop");
  ASSERT_TRUE(waitFor(
      [&] { return dds_test::Ros2Peer::matched(cmd_vel) && dds_test::Ros2Peer::matched(e_stop); }));
  ASSERT_TRUE(dds_test::writeBool(e_stop, true));
  ASSERT_TRUE(waitFor([&] { return status.value("engaged") == "True"; }));
  std::vector<dds_test::HostileSample> samples = dds_test::hostileTwists(true);
  for (auto& sample : samples) sample.refused = true;  // every one, by the e-stop
  expectRefused(cmd_vel, samples, "refused: cmd_vel", status, rest);
  ASSERT_TRUE(dds_test::writeBool(e_stop, false));
  expectTheBaseStillDrives();
}

/// How often `text` stands in `output`.
std::size_t occurrences(const std::string& output, const std::string& text) {
  std::size_t count = 0;
  for (std::size_t at = output.find(text); at != std::string::npos;
       at = output.find(text, at + 1)) {
    ++count;
  }
  return count;
}

TEST_F(DdsDriver, MalformedCdrOnEveryInputIsDroppedAndTheDriverGoesOn) {
  dds_test::EStopStatus status(*peer_);
  const AtRest rest = bringToRest();
  for (const dds_test::MalformedInput& input : dds_test::malformedInputs()) {
    SCOPED_TRACE(input.topic);
    const dds_entity_t writer = peer_->rawWriter(input.dds_type, input.topic);
    ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(writer); }));
    const std::string key = std::string("inputs refused: ") + input.counted;
    const uint64_t before = status.count(key);
    // What Cyclone's deserializer says of each sample it drops, on the driver's stderr.
    const std::string dropped =
        std::string("deserialization ") + input.topic + "/" + input.dds_type + " failed";
    const std::size_t dropped_before = occurrences(driver_->output(), dropped);
    for (const std::vector<uint8_t>& payload : input.payloads) {
      ASSERT_EQ(dds_test::writeRaw(writer, payload), DDS_RETCODE_OK);
    }
    // Every malformed payload is dropped, and said so; only the last, well-formed one reaches the
    // core (and is refused there).
    const std::size_t malformed = input.payloads.size() - (*input.counted != 0 ? 1 : 0);
    EXPECT_TRUE(waitFor([&] {
      return occurrences(driver_->output(), dropped) == dropped_before + malformed;
    })) << occurrences(driver_->output(), dropped) - dropped_before
        << " of " << malformed;
    if (*input.counted != 0) {
      EXPECT_TRUE(status.waitForCount(key, before + 1)) << status.count(key);
    }
    ASSERT_TRUE(driver_->running());
    EXPECT_TRUE(atRest() == rest);
  }
  // Had Cyclone taken the Bool of 2, it would have engaged the e-stop: released all the same.
  const dds_entity_t e_stop = peer_->writer(std_msgs_msg_dds__Bool__desc, "rt/e_stop");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(e_stop); }));
  ASSERT_TRUE(dds_test::writeBool(e_stop, false));
  expectTheBaseStillDrives();
}

/// SRD_DDS_FUZZ_COUNT (default 40) seeded random picks (SRD_FUZZ_SEED, default from the clock) of
/// the hostile samples and of random bytes on every input (scripts/fuzz_dds_interface.sh runs it
/// long): the driver lives through them and drives the base afterwards.
TEST_F(DdsDriver, SeededRandomHostileInputLeavesTheDriverWorking) {
  const char* seed_text = std::getenv("SRD_FUZZ_SEED");
  const char* count_text = std::getenv("SRD_DDS_FUZZ_COUNT");
  const uint64_t seed = seed_text ? std::stoull(seed_text) : static_cast<uint64_t>(time(nullptr));
  const int count = count_text ? std::stoi(count_text) : 40;
  std::cout << "dds fuzz: seed " << seed << ", " << count << " inputs" << std::endl;
  std::mt19937_64 rng(seed);
  std::vector<std::pair<dds_entity_t, dds_test::HostileSample>> pool;
  const auto add = [&](const dds_topic_descriptor_t& type, const char* topic,
                       const std::vector<dds_test::HostileSample>& samples) {
    const dds_entity_t writer = peer_->writer(type, topic);
    ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(writer); }));
    for (const auto& sample : samples) pool.emplace_back(writer, sample);
  };
  add(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel", dds_test::hostileTwists(true));
  add(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel", dds_test::hostileTwists(false));
  add(geometry_msgs_msg_dds__TwistStamped__desc, "rt/cmd_vel_stamped",
      dds_test::hostileStampedTwists());
  add(sensor_msgs_msg_dds__JointState__desc, "rt/joint_commands",
      dds_test::hostileJointCommands(kJoints));
  add(trajectory_msgs_msg_dds__JointTrajectory__desc, "rt/joint_trajectory",
      dds_test::hostileTrajectories(kJoints));
  std::vector<dds_entity_t> raw_writers;
  for (const dds_test::MalformedInput& input : dds_test::malformedInputs()) {
    raw_writers.push_back(peer_->rawWriter(input.dds_type, input.topic));
  }
  ASSERT_TRUE(waitFor([&] {
    for (dds_entity_t writer : raw_writers) {
      if (!dds_test::Ros2Peer::matched(writer)) return false;
    }
    return true;
  }));
  // In batches, each acknowledged by the driver before the next: its readers keep the last 10
  // samples, so an unpaced flood would mostly be dropped unread.
  std::set<dds_entity_t> written;
  for (int i = 0; i < count && driver_->running(); ++i) {
    if (rng() % 3 == 0) {  // random bytes of a random length on a random input
      std::vector<uint8_t> bytes(rng() % 96);
      for (uint8_t& byte : bytes) byte = static_cast<uint8_t>(rng());
      const dds_entity_t writer = raw_writers[rng() % raw_writers.size()];
      dds_test::writeRaw(writer, bytes);
      written.insert(writer);
    } else {
      const auto& [writer, sample] = pool[rng() % pool.size()];
      sample.write(writer);
      written.insert(writer);
    }
    if (i % 8 == 7) {
      for (dds_entity_t writer : written) dds_wait_for_acks(writer, DDS_SECS(10));
      written.clear();
    }
  }
  ASSERT_TRUE(driver_->running()) << "seed " << seed;
  const dds_entity_t e_stop = peer_->writer(std_msgs_msg_dds__Bool__desc, "rt/e_stop");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(e_stop); }));
  ASSERT_TRUE(dds_test::writeBool(e_stop, false));  // random bytes may have engaged it
  expectTheBaseStillDrives();
  EXPECT_TRUE(driver_->running()) << "seed " << seed;
}

// Last: SIGTERM ends the driver as it ends driver_node, the base's zero-speed frame written.
TEST_F(DdsDriver, ZSigtermStopsTheBaseAndExitsZero) {
  const dds_entity_t cmd_vel = peer_->writer(geometry_msgs_msg_dds__Twist__desc, "rt/cmd_vel");
  ASSERT_TRUE(waitFor([&] { return dds_test::Ros2Peer::matched(cmd_vel); }));
  const dds_test::TwistStream driving(cmd_vel, 0.2);
  ASSERT_TRUE(baseHoldsSpeed(true));
  driver_->signal(SIGTERM);
  const std::optional<int> status = driver_->waitExit(30.0);
  ASSERT_TRUE(status);
  EXPECT_TRUE(WIFEXITED(*status) && WEXITSTATUS(*status) == 0) << *status;
  EXPECT_TRUE(waitFor([] {
    const auto stats = baseStats(robot_stats());
    return stats.last_left_speed == 0 && stats.last_right_speed == 0;
  })) << "the driver's last words: a zero-speed frame";
}

/// dds_driver's exit status and output for `args` (it ends by itself).
std::pair<int, std::string> runToTheEnd(const std::vector<std::string>& args) {
  test_support::ChildProcess driver(SRD_DDS_DRIVER, args);
  const std::optional<int> status = driver.waitExit(30.0);
  EXPECT_TRUE(status && WIFEXITED(*status));
  return {status && WIFEXITED(*status) ? WEXITSTATUS(*status) : -1, driver.output()};
}

TEST(DdsDriverCommandLine, ABadParameterStopsItNamingTheParameter) {
  const std::string config = "/tmp/srd_test_dds_driver_bad_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(config) << "ros2: {domain_id: 500}\n";
  const auto [status, output] = runToTheEnd({"--config", config});
  std::remove(config.c_str());
  EXPECT_EQ(status, 2);
  EXPECT_NE(output.find("~ros2/domain_id"), std::string::npos) << output;
}

TEST(DdsDriverCommandLine, AnUnknownArgumentOrNoConfigIsRefusedWithTheUsage) {
  for (const auto& args :
       {std::vector<std::string>{"--config"}, std::vector<std::string>{"--conifg", "robot.yaml"},
        std::vector<std::string>{}}) {
    const auto [status, output] = runToTheEnd(args);
    EXPECT_EQ(status, 2) << output;
    EXPECT_NE(output.find("usage: dds_driver --config FILE"), std::string::npos) << output;
  }
}

}  // namespace
