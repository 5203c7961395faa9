// The echo device through the simulator: robot_sim hosts it from the registry (it names no echo),
// next to the built-in devices or alone, and the controller's round trips against it.
#include <gtest/gtest.h>

#include "serial_robot_driver/devices/echo/echo_codec.h"
#include "serial_robot_driver/devices/echo/echo_controller.h"
#include "serial_robot_driver/devices/echo/sim/echo_sim.h"
#include "support/sim_host.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::echo::sim {
namespace {

using namespace serial_robot_driver::sim::sim_test;  // NOLINT: the shared fixture

const Bytes kRequest123 = {0xE5, 0x01, 0x03, 0x01, 0x02, 0x03, 0xE7};
const Bytes kAnswer123 = {0xE5, 0x02, 0x03, 0x01, 0x02, 0x03, 0xE4};

FramerConfig echoHost() { return test_support::driverFramer({"base", "echo"}); }

std::string statsLine(const std::string& text, const std::string& key) {
  const std::size_t at = text.find(key + " ");
  return at == std::string::npos ? "" : text.substr(at, text.find('\n', at) - at);
}

TEST(EchoSim, AnswersEachRequestWithItsPayload) {
  EchoSim sim(serial_robot_driver::sim::Clock::duration::zero());
  serial_robot_driver::sim::Outbox out;
  sim.handleFrame(kRequestFrames, kRequest123.data(), kRequest123.size(),
                  serial_robot_driver::sim::Clock::now(), &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].bytes, kAnswer123);

  EchoSim slow(std::chrono::milliseconds(5));
  out.clear();
  const serial_robot_driver::sim::TimePoint at = serial_robot_driver::sim::Clock::now();
  slow.handleFrame(kRequestFrames, kRequest123.data(), kRequest123.size(), at, &out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(slow.nextEvent(), at + std::chrono::milliseconds(5));
  serial_robot_driver::sim::SimWorld world;
  slow.tick(at + std::chrono::milliseconds(5), world, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(slow.stats().answers, 1u);
}

TEST(EchoSim, RobotSimHostsItOnTheSharedPortNextToTheBase) {
  serial_robot_driver::sim::SimOptions options = onlyBase();
  base::sim::baseConfig(options).battery_percent = 64;
  options.device("echo").enabled = true;
  serial_robot_driver::sim::RobotSim sim(options);
  sim.start();
  ASSERT_EQ(sim.ports().size(), 1u);
  EXPECT_EQ(sim.ports()[0].devices, (std::vector<std::string>{"base", "echo"}));
  Host host(slaveOf(sim), echoHost());
  ASSERT_TRUE(host.ok());
  host.send(kBatteryRequestSeq1);
  host.send(kRequest123);
  EXPECT_TRUE(host.waitForFrame(kAnswer123));
  EXPECT_TRUE(host.waitForFrame(kBattery64ReplySeq0));
  EXPECT_TRUE(waitForStats(sim, [](const serial_robot_driver::sim::SimStats& s) {
    return s.findDevice("echo") != nullptr;
  }));
  const std::string text = serial_robot_driver::sim::formatStats(sim.stats());
  EXPECT_EQ(statsLine(text, "echo_requests"), "echo_requests 1");
  EXPECT_EQ(statsLine(text, "echo_answers"), "echo_answers 1");
  EXPECT_EQ(statsLine(text, "frames_for_absent_device"), "frames_for_absent_device 0");
}

TEST(EchoSim, NotHostedUnlessAskedForAndItsRequestsAreThenForNobody) {
  serial_robot_driver::sim::RobotSim sim(onlyBase());
  sim.start();
  EXPECT_EQ(sim.ports()[0].devices, (std::vector<std::string>{"base"}));
  Host host(slaveOf(sim), echoHost());
  ASSERT_TRUE(host.ok());
  host.send(kRequest123);
  EXPECT_TRUE(waitForStats(sim, [](const serial_robot_driver::sim::SimStats& s) {
    return s.frames_for_absent_device == 1;
  }));
  EXPECT_EQ(serial_robot_driver::sim::formatStats(sim.stats()).find("echo_"), std::string::npos);
}

TEST(EchoSim, CommandLineHostsItAloneOnItsOwnLink) {
  TempDir dir;
  const std::string link = dir.file("robot");
  const std::string latency = "--echo-latency-ms=2";
  const char* argv[] = {"robot_sim",   "--no-base",  "--no-body",    "--no-servo-bus",
                        "--echo-link", link.c_str(), latency.c_str()};
  const serial_robot_driver::sim::CommandLine parsed =
      serial_robot_driver::sim::parseCommandLine(7, argv);
  ASSERT_EQ(parsed.error, "");
  ASSERT_TRUE(parsed.options.hosts("echo"));
  EXPECT_EQ(parsed.options.findDevice("echo")->settings.at("latency-ms"), "2");
  EXPECT_NE(serial_robot_driver::sim::usage().find("--echo-link PATH"), std::string::npos);
  EXPECT_FALSE(serial_robot_driver::sim::parseCommandLine(1, argv).options.hosts("echo"))
      << "off by default";
  const char* bad[] = {"robot_sim", "--echo-latency-ms", "soon"};
  EXPECT_THROW(
      serial_robot_driver::sim::RobotSim(serial_robot_driver::sim::parseCommandLine(3, bad).options)
          .start(),
      std::invalid_argument);

  serial_robot_driver::sim::RobotSim sim(parsed.options);
  sim.start();
  ASSERT_EQ(sim.ports().size(), 1u);
  EXPECT_EQ(sim.ports()[0].link, link);

  // The driver's controller on a link to it: round trips, counted.
  core::SerialLinkOptions link_options;
  link_options.path = link;
  link_options.framer = test_support::driverFramer({"echo"});
  core::SerialLink serial(link_options);
  EchoController controller(serial.writer(), std::chrono::milliseconds(500));
  serial.addListener(&controller);
  serial.start();
  ASSERT_TRUE(test_support::waitFor([&] { return serial.connected(); }, 3.0));
  for (int i = 0; i < 3; ++i) {
    const PingResult result = controller.ping();
    EXPECT_TRUE(result.ok) << result.error;
    EXPECT_GE(result.round_trip, std::chrono::milliseconds(2));
  }
  serial.stop();
  const EchoStats stats = controller.stats();
  EXPECT_EQ(stats.pings, 3u);
  EXPECT_EQ(stats.round_trips, 3u);
  EXPECT_EQ(stats.mismatches + stats.timeouts, 0u);
  EXPECT_FALSE(stats.last_ping_failed);
  EXPECT_FALSE(controller.ping().ok) << "the port is closed";
  EXPECT_TRUE(controller.stats().last_ping_failed);
}

TEST(EchoController, CountsTimeoutsAndMismatchedAnswers) {
  std::vector<Bytes> written;
  EchoController controller(
      [&written](const Bytes& frame) {
        written.push_back(frame);
        return true;
      },
      std::chrono::milliseconds(20));
  const PingResult silent = controller.ping();
  EXPECT_FALSE(silent.ok);
  ASSERT_EQ(written.size(), 1u);
  const auto payload = decode(kRequestType, written[0].data(), written[0].size());
  ASSERT_TRUE(payload.ok());
  // Its answer comes too late: nothing is waiting for it any more.
  const Bytes late = encodeAnswer(*payload);
  controller.onFrame(kAnswerFrames, late.data(), late.size(),
                     serial_robot_driver::sim::Clock::now());
  const EchoStats stats = controller.stats();
  EXPECT_EQ(stats.timeouts, 1u);
  EXPECT_EQ(stats.mismatches, 1u);
  EXPECT_EQ(stats.round_trips, 0u);
  EXPECT_TRUE(stats.last_ping_failed);
}

}  // namespace
}  // namespace serial_robot_driver::devices::echo::sim
