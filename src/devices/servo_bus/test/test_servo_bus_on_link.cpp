// serial_robot_driver::devices::servo_bus::ServoBus as the driver runs it: its worker on the port's
// reader thread (runOn), against the simulated servos over a real pseudo-terminal. The schedules
// themselves are tested on a manual clock in test_servo_bus.cpp; these tests are about the threads:
// the poll reads its own answers on the reader thread, callers on other threads are still answered
// (the reader reads for them, also while it waits for the bus), a move from another thread wakes
// the idle reader, and an unplugged port ends a poll at once.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"
#include "serial_robot_driver/devices/servo_bus/servo_bus.h"
#include "serial_robot_driver/devices/servo_bus/sim/servo_bus_sim.h"
#include "serial_robot_driver/sim/robot_sim.h"
#include "support/framer_configs.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using std::chrono::milliseconds;

constexpr double kWaitSeconds = 5.0;  // generous: the machine may be busy

/// The simulated servo bus on a pty and the driver's side of it: one link, one bus on it.
struct BusOnLink {
  explicit BusOnLink(const std::string& name, ServoBusConfig config,
                     std::vector<uint8_t> sim_ids = {1, 2, 3}) {
    serial_robot_driver::sim::SimOptions options;
    options.device("base").enabled = false;
    options.device("body").enabled = false;
    sim::servoBusConfig(options).servo_ids = std::move(sim_ids);
    sim::servoBusConfig(options).answer_latency_s = 0.0;
    options.link = "/tmp/srd_bus_on_link_" + name + "_" + std::to_string(::getpid());
    sim = std::make_unique<serial_robot_driver::sim::RobotSim>(options);
    sim->start();

    core::SerialLinkOptions link_options;
    link_options.path = options.link;
    link_options.reconnect_interval = 0.05;
    link_options.framer = test_support::driverFramer({"servo_bus"});
    link_options.stale_frame_timeout = config.client.timeout;
    link = std::make_unique<core::SerialLink>(link_options);

    ServoBusEvents events;
    events.on_angle = [this](const ServoAngleSample&) {
      ++angles;
      if (!link->onReaderThread()) ++angles_off_reader;
    };
    bus = std::make_unique<ServoBus>(std::move(config), link->writer(), std::move(events));
    bus->runOn(*link);
    link->start();
    bus->start();
  }
  ~BusOnLink() {
    bus->shutdown();
    link->stop();  // before the bus it calls goes away
  }

  std::unique_ptr<serial_robot_driver::sim::RobotSim> sim;
  std::unique_ptr<core::SerialLink> link;
  std::unique_ptr<ServoBus> bus;
  std::atomic<int> angles{0};
  std::atomic<int> angles_off_reader{0};
};

ServoBusConfig polling(std::vector<uint8_t> ids, double rate_hz) {
  ServoBusConfig config;
  config.polled_ids = std::move(ids);
  config.poll_rate = rate_hz;
  config.health_rate = 0.0;
  config.read_identity = false;  // these tests count the angle polls' transactions
  config.client.timeout = milliseconds(500);
  return config;
}

TEST(ServoBusOnLink, PollsOnTheReaderThreadWhileCallersAreAnswered) {
  // Polled as fast as the pty goes: the bus is never idle, so every call competes with the poll.
  BusOnLink rig("busy", polling({1, 2, 3}, 1000.0));
  ASSERT_TRUE(test_support::waitFor([&] { return rig.angles >= 50; }, kWaitSeconds));

  // Two callers on two threads, as two service calls: each transaction of theirs is read by the
  // reader thread, between (or while it waits to do) its own polls.
  std::atomic<int> failures{0};
  auto caller = [&](uint8_t id) {
    for (int i = 0; i < 20; ++i) {
      ServoParamValue voltage;
      if (!rig.bus->client().ping(id).ok()) ++failures;
      if (!rig.bus->client().readParam(id, "voltage", &voltage).ok()) ++failures;
    }
  };
  std::thread first(caller, 1);
  std::thread second(caller, 3);
  first.join();
  second.join();
  EXPECT_EQ(failures, 0);

  const int before = rig.angles;
  ASSERT_TRUE(test_support::waitFor([&] { return rig.angles >= before + 50; }, kWaitSeconds))
      << "the poll goes on after the calls";
  EXPECT_EQ(rig.angles_off_reader, 0) << "every poll ran on the link's reader thread";
  const ServoBusStats stats = rig.bus->client().stats();
  EXPECT_EQ(stats.timeouts, 0u);
  EXPECT_EQ(stats.mismatched, 0u);
  EXPECT_EQ(stats.garbled, 0u);
}

TEST(ServoBusOnLink, AMoveFromAnotherThreadWakesTheIdleReader) {
  // Nothing polled: the reader sleeps in its read (seconds at a time) until woken.
  BusOnLink rig("move", polling({}, 10.0));
  ASSERT_TRUE(rig.link->waitConnected(milliseconds(3000)));
  MoveRequest move;
  move.id = 2;
  move.angle_deg = 30.0;
  rig.bus->queueMoves({move});
  ASSERT_TRUE(
      test_support::waitFor([&] { return rig.bus->stats().moves_sent == 1; }, kWaitSeconds));
  ASSERT_TRUE(test_support::waitFor(
      [&] { return sim::servoBusStats(rig.sim->stats()).requests >= 1; }, kWaitSeconds));
  EXPECT_EQ(rig.bus->stats().moves_failed, 0u);
}

TEST(ServoBusOnLink, ShutdownSaysItsLastWordsThroughTheRunningReader) {
  ServoBusConfig config = polling({1, 2}, 200.0);
  config.on_shutdown = ShutdownAction::kStop;
  BusOnLink rig("shutdown", config);
  ASSERT_TRUE(test_support::waitFor([&] { return rig.angles >= 10; }, kWaitSeconds));
  SpinRequest spin;
  spin.id = 1;
  spin.mode = 1;  // continuous
  spin.speed_dps = 90;
  ASSERT_TRUE(rig.bus->spin(spin).ok());
  EXPECT_EQ(rig.bus->movingIds(), std::vector<uint8_t>{1});
  const uint64_t requests_before = sim::servoBusStats(rig.sim->stats()).requests;
  rig.bus->shutdown();
  EXPECT_TRUE(rig.bus->movingIds().empty()) << "the SPIN stop went out";
  ASSERT_TRUE(test_support::waitFor(
      [&] { return sim::servoBusStats(rig.sim->stats()).requests > requests_before; },
      kWaitSeconds));
  EXPECT_EQ(rig.bus->client().ping(1).error, ServoError::kShutdown);
}

TEST(ServoBusOnLink, ASilentServoIsBackedOffWithoutHoldingUpTheOthers) {
  // Servo 9 is not on the bus: each of its polls waits out the timeout on the reader thread.
  ServoBusConfig config = polling({1, 9}, 100.0);
  config.client.timeout = milliseconds(100);
  BusOnLink rig("silent", config);
  ASSERT_TRUE(test_support::waitFor(
      [&] { return rig.bus->stats().offline_ids == std::vector<uint8_t>{9}; }, kWaitSeconds));
  const int before = rig.angles;
  ASSERT_TRUE(test_support::waitFor([&] { return rig.angles >= before + 20; }, kWaitSeconds));
  EXPECT_EQ(rig.angles_off_reader, 0);
  EXPECT_TRUE(rig.bus->client().ping(1).ok());
  EXPECT_EQ(rig.bus->client().ping(9).error, ServoError::kTimeout);
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
