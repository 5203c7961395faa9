// core::CaptureQueue (core/capture_queue.h): chunks are published in order on the queue's own
// thread, never more than max_in_flight at once held by the middleware, the queue bounded at
// max_queued with every chunk beyond it counted as dropped, and stop() never waits on a stalled
// subscriber. The "middleware" here keeps the in-flight tokens in a list until the test lets go.
#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "serial_robot_driver/core/capture_queue.h"
#include "support/test_helpers.h"

namespace serial_robot_driver::core {
namespace {

constexpr double kTimeout = 10.0;  // s: an upper bound for a busy machine

class CaptureQueueTest : public ::testing::Test {
 protected:
  /// A publication of `bytes` bytes named `name` that the middleware keeps (its token held).
  CaptureQueue::Publication kept(CaptureQueue& queue, const std::string& name, std::size_t bytes) {
    return [this, &queue, name, bytes] {
      std::lock_guard<std::mutex> lock(mutex_);
      published_.push_back(name);
      held_.push_back(queue.holdInFlight());
      return bytes;
    };
  }
  void letGo() {
    std::lock_guard<std::mutex> lock(mutex_);
    held_.clear();
  }
  std::vector<std::string> published() {
    std::lock_guard<std::mutex> lock(mutex_);
    return published_;
  }

  std::mutex mutex_;
  std::vector<std::string> published_;
  std::vector<std::shared_ptr<void>> held_;
};

TEST_F(CaptureQueueTest, PublishesInOrderAndCountsChunksAndBytes) {
  CaptureQueue queue({});
  EXPECT_TRUE(queue.push(kept(queue, "a", 3)));
  EXPECT_TRUE(queue.push(kept(queue, "b", 0)));
  EXPECT_TRUE(queue.push(kept(queue, "c", 1000000)));
  ASSERT_TRUE(test_support::waitFor([&] { return queue.stats().chunks == 3; }, kTimeout));
  EXPECT_EQ(published(), (std::vector<std::string>{"a", "b", "c"}));
  const WireCaptureStats stats = queue.stats();
  EXPECT_EQ(stats.bytes, 1000003u);
  EXPECT_EQ(stats.in_roscpp, 3u);
  EXPECT_EQ(stats.dropped, 0u);
  letGo();
  EXPECT_EQ(queue.stats().in_roscpp, 0u);
}

TEST_F(CaptureQueueTest, AFullMiddlewareHoldsThePublishingBackAndAFullQueueDropsAndCounts) {
  CaptureQueue queue({3, 2});  // 3 queued, 2 in flight
  for (int i = 0; i < 2; ++i) queue.push(kept(queue, "held", 1));
  ASSERT_TRUE(test_support::waitFor([&] { return queue.stats().in_roscpp == 2; }, kTimeout));
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(queue.push(kept(queue, "later", 1)));
  EXPECT_FALSE(queue.push(kept(queue, "lost", 1)));
  WireCaptureStats stats = queue.stats();
  EXPECT_EQ(stats.chunks, 2u) << "nothing more while the middleware holds two";
  EXPECT_EQ(stats.queued, 3u);
  EXPECT_EQ(stats.dropped, 1u);

  letGo();  // room again: the queued ones go out, two at a time at most
  ASSERT_TRUE(test_support::waitFor([&] { return queue.stats().chunks >= 4; }, kTimeout));
  EXPECT_LE(queue.stats().in_roscpp, 2u);
  letGo();
  ASSERT_TRUE(test_support::waitFor([&] { return queue.stats().chunks == 5; }, kTimeout));
  EXPECT_EQ(published().size(), 5u);
  EXPECT_EQ(queue.stats().dropped, 1u);
}

TEST_F(CaptureQueueTest, StoppingWhileASubscriberStallsDropsTheRestInsteadOfWaiting) {
  CaptureQueue queue({100, 1});
  queue.push(kept(queue, "held", 1));
  ASSERT_TRUE(test_support::waitFor([&] { return queue.stats().in_roscpp == 1; }, kTimeout));
  for (int i = 0; i < 5; ++i) queue.push(kept(queue, "stuck", 1));
  queue.stop();  // returns although the token is still held
  const WireCaptureStats stats = queue.stats();
  EXPECT_EQ(stats.chunks, 1u);
  EXPECT_EQ(stats.dropped, 5u);
  EXPECT_EQ(stats.queued, 0u);
  EXPECT_FALSE(queue.push(kept(queue, "after", 1))) << "nothing is queued after stop()";
  EXPECT_EQ(queue.stats().dropped, 6u);
  queue.stop();  // idempotent
}

TEST_F(CaptureQueueTest, StoppingPublishesWhatIsQueuedWhileThereIsRoom) {
  CaptureQueue queue({});
  for (int i = 0; i < 100; ++i) queue.push(kept(queue, "x", 2));
  queue.stop();
  EXPECT_EQ(queue.stats().chunks, 100u);
  EXPECT_EQ(queue.stats().bytes, 200u);
  EXPECT_EQ(queue.stats().dropped, 0u);
}

TEST_F(CaptureQueueTest, ATokenMayOutliveTheQueue) {
  std::shared_ptr<void> token;
  {
    CaptureQueue queue({});
    token = queue.holdInFlight();
    EXPECT_EQ(queue.stats().in_roscpp, 1u);
  }
  token.reset();  // the middleware lets go after the capture is gone: nothing to crash into
  SUCCEED();
}

TEST_F(CaptureQueueTest, ZeroLimitsDropEverythingWithoutBlocking) {
  CaptureQueue no_room({0, 0});
  EXPECT_FALSE(no_room.push(kept(no_room, "a", 1)));
  EXPECT_EQ(no_room.stats().dropped, 1u);
  CaptureQueue never_in_flight({10, 0});
  EXPECT_TRUE(never_in_flight.push(kept(never_in_flight, "b", 1)));
  never_in_flight.stop();
  EXPECT_EQ(never_in_flight.stats().chunks, 0u);
  EXPECT_EQ(never_in_flight.stats().dropped, 1u);
}

}  // namespace
}  // namespace serial_robot_driver::core
