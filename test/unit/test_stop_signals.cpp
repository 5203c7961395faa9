// core::StopSignals (core/stop_signals.h): a SIGINT or SIGTERM sent to the waiting thread ends the
// wait (and does not end the process), as do `running` turning false and `done`. The test thread's
// signal mask is restored afterwards (the signals are thread-directed: no other thread sees them).
#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>

#include <chrono>

#include "serial_robot_driver/core/stop_signals.h"

namespace serial_robot_driver::core {
namespace {

using std::chrono::milliseconds;

class StopSignalsTest : public ::testing::Test {
 protected:
  void SetUp() override { pthread_sigmask(SIG_SETMASK, nullptr, &saved_mask_); }
  void TearDown() override {
    // A signal a failed wait left pending must not reach the test process once unblocked.
    sigset_t stop_signals;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    const timespec now{0, 0};
    while (sigtimedwait(&stop_signals, nullptr, &now) > 0) {
    }
    pthread_sigmask(SIG_SETMASK, &saved_mask_, nullptr);
  }
  sigset_t saved_mask_;
};

TEST_F(StopSignalsTest, ASignalToTheWaitingThreadEndsTheWaitInsteadOfTheProcess) {
  const StopSignals stop;
  for (int signal : {SIGTERM, SIGINT}) {
    pthread_kill(pthread_self(), signal);  // blocked: pending until the wait takes it
    EXPECT_FALSE(stop.wait(milliseconds(10000))) << signal;
  }
}

TEST_F(StopSignalsTest, DoneEndsTheWaitAndSaysSo) {
  const StopSignals stop;
  int checks = 0;
  EXPECT_TRUE(stop.wait(
      milliseconds(0), [] { return true; }, [&] { return ++checks == 3; }))
      << "a period of 0 checks without waiting";
  EXPECT_EQ(checks, 3);
}

TEST_F(StopSignalsTest, NoLongerRunningEndsTheWait) {
  const StopSignals stop;
  int checks = 0;
  EXPECT_FALSE(stop.wait(milliseconds(1), [&] { return ++checks < 3; }));
  EXPECT_EQ(checks, 3);
  EXPECT_FALSE(stop.wait(
      milliseconds(1), [] { return false; }, [] { return true; }))
      << "no longer running comes first";
}

TEST_F(StopSignalsTest, AHugeOrNegativePeriodStillTakesThePendingSignal) {
  const StopSignals stop;
  for (milliseconds period : {milliseconds::max(), milliseconds(-5), milliseconds::min()}) {
    pthread_kill(pthread_self(), SIGTERM);
    int checks = 0;
    EXPECT_FALSE(stop.wait(period, [&] { return ++checks <= 1000; })) << period.count();
    EXPECT_EQ(checks, 1) << "taken at the first check, period " << period.count();
  }
  int checks = 0;
  EXPECT_TRUE(stop.wait(milliseconds(-1), {}, [&] { return ++checks == 2; }));
}

}  // namespace
}  // namespace serial_robot_driver::core
