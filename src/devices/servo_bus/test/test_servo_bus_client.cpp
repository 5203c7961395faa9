// ServoBusClient's transactions against a fake bus (servo_bus_client_fixture.h): answers matched,
// retried, echoed and mismatched, concurrent callers, a port that is down or lost, the shutdown;
// and the bus lock's priorities.
#include <gtest/gtest.h>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "support/servo_bus_client_fixture.h"

namespace serial_robot_driver::devices::servo_bus {
namespace {

using protocol::FrameFamily;
using namespace golden::servo;  // NOLINT: the frames shared with the rostest

TEST_F(ServoBusClientTest, PingOnlineSendsGoldenRequest) {
  bus_.answer(kPing3, {kPing3Reply});
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written, std::vector<Bytes>{kPing3});
  EXPECT_NE(status.message.find("servo 3 is online"), std::string::npos) << status.message;
  const ServoBusStats stats = client_.stats();
  EXPECT_EQ(stats.transactions, 1u);
  EXPECT_EQ(stats.retries, 0u);
  EXPECT_EQ(stats.timeouts, 0u);
}

TEST_F(ServoBusClientTest, PingOfflineTriesRetriesPlusOneTimes) {
  const ServoStatus status = client_.ping(7);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_EQ(status.message, "servo 7 did not answer PING within 20 ms (2 attempts)");
  EXPECT_EQ(bus_.written, (std::vector<Bytes>{kPing7, kPing7}));
  const ServoBusStats stats = client_.stats();
  EXPECT_EQ(stats.transactions, 1u);
  EXPECT_EQ(stats.retries, 1u);
  EXPECT_EQ(stats.timeouts, 1u);
}

TEST_F(ServoBusClientTest, AnswerToTheRetryCompletesTheTransaction) {
  bus_.answer(kPing3, {kPing3Reply}, /*first_answered_write=*/2);
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(bus_.written.size(), 2u);
  EXPECT_EQ(client_.stats().retries, 1u);
  EXPECT_EQ(client_.stats().timeouts, 0u);
}

TEST_F(ServoBusClientTest, MismatchedAnswersAreCountedAndIgnored) {
  // Another servo's PING answer and an answer to another command come first.
  bus_.answer(kPing3, {kPing4Reply, kReadAngle0Reply902, kPing3Reply});
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(client_.stats().mismatched, 2u);
  EXPECT_EQ(bus_.written.size(), 1u);
}

TEST_F(ServoBusClientTest, OnlyMismatchedAnswersMeanOffline) {
  bus_.answer(kPing7, {kPing4Reply});
  const ServoStatus status = client_.ping(7);
  EXPECT_EQ(status.error, ServoError::kTimeout);
  EXPECT_EQ(client_.stats().mismatched, 2u);
}

TEST_F(ServoBusClientTest, EchoOfOurRequestIsSkipped) {
  bus_.echo = true;
  bus_.answer(kPing3, {kPing3Reply});
  const ServoStatus status = client_.ping(3);
  EXPECT_TRUE(status.ok()) << status.message;
  EXPECT_EQ(client_.stats().echoes, 1u);
  EXPECT_EQ(client_.stats().mismatched, 0u);
}

TEST_F(ServoBusClientTest, AnswerOfTheWrongShapeIsReportedAsMalformed) {
  bus_.answer(kPing3, {kPing3ReplyTooLong});
  const ServoStatus status = client_.ping(3);
  EXPECT_EQ(status.error, ServoError::kBadAnswer);
  EXPECT_EQ(bus_.written.size(), 2u);  // re-sent once
  EXPECT_EQ(client_.stats().garbled, 2u);
}

TEST_F(ServoBusClientTest, AnswersArrivingWithoutARequestAreMismatched) {
  client_.onFrame(kResponseFrames, kPing3Reply.data(), kPing3Reply.size(), core::Clock::now());
  EXPECT_EQ(client_.stats().mismatched, 1u);
}

TEST(ServoBusClientThreadsTest, ConcurrentCallersAreServedOneAfterTheOther) {
  FakeBus bus;
  bus.from_other_thread = true;
  ServoBusOptions options;
  options.timeout = std::chrono::milliseconds(5000);  // generous: the answer comes from a thread
  ServoBusClient client(options, [&bus](const Bytes& frame) { return bus.write(frame); });
  bus.client = &client;
  bus.answer(kPing3, {kPing3Reply});
  bus.answer(kReadVoltage3, {kReadVoltage3Reply});

  ServoStatus ping_status;
  std::thread pinger([&] { ping_status = client.ping(3); });
  ServoParamValue voltage;
  const ServoStatus read_status = client.readParam(3, "voltage", &voltage);
  pinger.join();
  bus.joinAnswerThreads();
  EXPECT_TRUE(ping_status.ok()) << ping_status.message;
  EXPECT_TRUE(read_status.ok()) << read_status.message;
  EXPECT_EQ(voltage.value, 7400);
  EXPECT_EQ(client.stats().transactions, 2u);
  EXPECT_EQ(client.stats().mismatched, 0u);
  EXPECT_EQ(bus.written.size(), 2u);
}

TEST_F(ServoBusClientTest, PortDownFailsFast) {
  bus_.connected = false;
  const ServoStatus status = client_.ping(3);
  EXPECT_EQ(status.error, ServoError::kNotConnected);
  EXPECT_EQ(status.message, "servo bus port is not connected");
  EXPECT_EQ(client_.stats().timeouts, 0u);
}

TEST_F(ServoBusClientTest, PortLostWhileWaitingFailsWithoutWaitingOut) {
  bus_.drop_link_on_write = true;
  const ServoStatus status = client_.ping(3);
  EXPECT_EQ(status.error, ServoError::kNotConnected);
  EXPECT_EQ(bus_.written.size(), 1u);  // not re-sent on a dead port
}

TEST_F(ServoBusClientTest, ShutdownFailsLaterCalls) {
  client_.shutdown();
  EXPECT_EQ(client_.ping(3).error, ServoError::kShutdown);
  EXPECT_TRUE(bus_.written.empty());
}

TEST(BusMutexTest, AWaitingForegroundCallerGoesBeforeBackgroundWork) {
  BusMutex bus;
  std::mutex order_mutex;
  std::vector<std::string> order;
  const auto record = [&](const char* who) {
    std::lock_guard<std::mutex> lock(order_mutex);
    order.push_back(who);
  };
  bus.lock();  // a transaction in progress
  std::thread foreground([&] {
    std::lock_guard<BusMutex> held(bus);
    record("foreground");
  });
  while (bus.foregroundWaiting() == 0) std::this_thread::yield();
  std::thread background([&] {
    bus.lockBackground();
    record("background");
    bus.unlock();
  });
  bus.unlock();
  foreground.join();
  background.join();
  EXPECT_EQ(order, (std::vector<std::string>{"foreground", "background"}));
}

}  // namespace
}  // namespace serial_robot_driver::devices::servo_bus
