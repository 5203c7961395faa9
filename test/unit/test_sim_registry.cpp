// robot_sim hosts every device through the simulator registry: each registered device alone, its
// flags in its own --help section, the chassis motion passed through the world, and a host that
// names no device.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "support/sim_host.h"

namespace serial_robot_driver::sim {
namespace {

using namespace sim_test;  // NOLINT: the shared fixture

/// The options that host `name` and nothing else.
SimOptions only(const std::string& name) {
  SimOptions options;
  for (const SimDeviceModule* module : registeredSimDevices()) {
    options.device(module->name).enabled = name == module->name;
  }
  return options;
}

TEST(SimRegistry, EveryRegisteredDeviceIsHostedAloneThroughItsModule) {
  ASSERT_GE(registeredSimDevices().size(), 4u);  // base, body, servo_bus, echo
  for (const SimDeviceModule* module : registeredSimDevices()) {
    SCOPED_TRACE(module->name);
    ASSERT_NE(module->make, nullptr);
    ASSERT_FALSE(module->outputs.empty());
    RobotSim sim(only(module->name));
    sim.start();
    ASSERT_EQ(sim.ports().size(), 1u);
    EXPECT_EQ(sim.ports()[0].devices, std::vector<std::string>{module->name});
    const SimStats stats = sim.stats();
    const DeviceSimStats* own = stats.findDevice(module->name);
    ASSERT_NE(own, nullptr);
    EXPECT_FALSE(own->counters.empty());
    EXPECT_FALSE(own->lines.empty());
    for (const OutputKind* kind : module->outputs) {
      const std::string text = formatStats(stats);
      EXPECT_NE(text.find(std::string(kind->name) + "_sent_intact "), std::string::npos);
    }
  }
}

TEST(SimRegistry, LeftOutDevicesKeepTheirStatsKeysAtZero) {
  RobotSim sim(only("servo_bus"));
  sim.start();
  const std::string text = formatStats(sim.stats());
  for (const char* expected : {"\nbase_resets 0\n", "\nleft_ticks 0\n", "\nrx_frames_base 0\n",
                               "\nbase_replies_sent_intact 0\n", "\nsync_writes_bad 0\n",
                               "\ntelemetry_discarded 0\n", "\nservo_requests 0\n"}) {
    EXPECT_NE(text.find(expected), std::string::npos) << expected << " missing from:\n" << text;
  }
  EXPECT_EQ(text.find("echo_"), std::string::npos) << "the tests' device has no keys unless hosted";
  EXPECT_EQ(devices::base::sim::baseStats(sim.stats()).resets, 0u);
}

TEST(SimRegistry, UnknownDeviceNamesAreRejected) {
  SimOptions options;
  EXPECT_THROW(options.device("lidar"), std::invalid_argument);
  EXPECT_FALSE(options.hosts("lidar"));
  EXPECT_TRUE(options.hosts("base"));   // the robot's own: hosted unless left out
  EXPECT_FALSE(options.hosts("echo"));  // the tests' device: only when asked for
}

/// The lines of `usage()` from `title` to the next blank line.
std::string helpSection(const std::string& title) {
  const std::string text = usage();
  const std::size_t start = text.find("\n" + title + "\n");
  if (start == std::string::npos) return "";
  return text.substr(start, text.find("\n\n", start + 1) - start);
}

TEST(SimRegistry, EachDeviceListsItsFlagsInItsOwnHelpSection) {
  std::set<std::string> seen;
  for (const SimDeviceModule* module : registeredSimDevices()) {
    SCOPED_TRACE(module->name);
    std::string title = module->description;
    title[0] = static_cast<char>(std::toupper(title[0]));
    title += " (" + std::string(module->name) +
             (module->hosted_by_default ? "" : "; not simulated unless asked for") + "):";
    const std::string section = helpSection(title);
    ASSERT_FALSE(section.empty()) << title << " missing from:\n" << usage();
    std::vector<std::string> flags{
        linkFlag(*module), (module->hosted_by_default ? "--no-" : "--") + flagName(module->name)};
    for (const SimDeviceOption& option : module->options) {
      flags.push_back(optionFlag(*module, option));
    }
    for (const std::string& flag : flags) {
      EXPECT_NE(section.find("  " + flag + " "), std::string::npos) << flag << " in:\n" << section;
      EXPECT_TRUE(seen.insert(flag).second) << flag << " declared twice";
    }
  }
  // Flags the users know, in their device's section with their help and default.
  EXPECT_NE(helpSection("AP1 base (base):").find("--turn-slip FRACTION"), std::string::npos);
  EXPECT_NE(helpSection("UART bus servos (servo_bus):")
                .find("--servo-latency-ms MS   servo bus answer latency (default 1.5)"),
            std::string::npos);
}

// The base writes the chassis motion into the world; the board's IMU reads it from there.
TEST(SimRegistry, TheBoardsImuReportsTheBasesTurnThroughTheWorld) {
  const TimePoint t0{};
  SimOptions options;
  devices::base::sim::baseConfig(options).turn_slip = 0.3;
  const auto base = findSimDevice("base")->make(options.device("base"), 1, t0);
  const auto body = findSimDevice("body")->make(options.device("body"), 2, t0);
  SimWorld world;
  Outbox out;
  base->handleFrame(devices::base::kFrames, kRight4Seq0.data(), kRight4Seq0.size(), t0, &out);
  for (int ms = 20; ms <= 200; ms += 20) {
    const TimePoint now = t0 + milliseconds(ms);
    base->tick(now, world, &out);
    body->tick(now, world, &out);
  }
  const auto base_stats = base->stats({}).counters.as<devices::base::sim::BaseSimStats>();
  const auto body_stats = body->stats({}).counters.as<devices::body::sim::BodySimStats>();
  EXPECT_GT(base_stats.yaw_rad, 0.0);  // right wheel faster: counter-clockwise
  EXPECT_DOUBLE_EQ(world.chassis.yaw_rad, base_stats.yaw_rad);
  EXPECT_NEAR(body_stats.yaw_rad, base_stats.yaw_rad, 1e-9);
}

/// Whole words and camel-case parts of `text`, lower case: "kBaseReply" -> k, base, reply.
std::set<std::string> wordParts(const std::string& text) {
  std::set<std::string> parts;
  static const std::regex kPart("[A-Z]?[a-z]+|[A-Z]+(?![a-z])|[0-9]+");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kPart);
       it != std::sregex_iterator(); ++it) {
    std::string part = it->str();
    for (char& c : part) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    parts.insert(part);
  }
  return parts;
}

TEST(SimRegistry, TheSimulatorHostNamesNoDevice) {
  namespace fs = std::filesystem;
  const fs::path root = SRD_SOURCE_DIR;
  std::set<std::string> device_words;  // "servo_bus" -> servo, bus
  for (const SimDeviceModule* module : registeredSimDevices()) {
    std::stringstream name(module->name);
    for (std::string word; std::getline(name, word, '_');) device_words.insert(word);
  }
  std::size_t files = 0;
  for (const fs::path& folder : {root / "src/sim", root / "include/serial_robot_driver/sim"}) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      std::ifstream in(entry.path());
      const std::string text((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
      ++files;
      EXPECT_EQ(text.find("serial_robot_driver/devices/"), std::string::npos) << entry.path();
      for (const std::string& word : wordParts(text)) {
        EXPECT_EQ(device_words.count(word), 0u) << entry.path() << " names '" << word << "'";
      }
    }
  }
  EXPECT_GE(files, 10u);
}

}  // namespace
}  // namespace serial_robot_driver::sim
