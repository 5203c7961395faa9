// ReadWaiter on a pipe: what ends a wait (input, a wake-up, a hang-up, the time-out), in which
// order when several are due, and that watching follows the fd a stream reopens with.
#include <gtest/gtest.h>
#include <unistd.h>

#include <thread>

#include "serial_robot_driver/transport/read_waiter.h"

namespace serial_robot_driver::transport {
namespace {

constexpr int kNoLimit = -1;

/// A pipe whose read end the waiter watches; closes whatever ends are still open.
struct Pipe {
  int read_end = -1;
  int write_end = -1;
  Pipe() {
    int ends[2];
    if (::pipe(ends) == 0) {
      read_end = ends[0];
      write_end = ends[1];
    }
  }
  ~Pipe() {
    closeWriteEnd();
    if (read_end >= 0) ::close(read_end);
  }
  void put(char byte) const { ASSERT_EQ(::write(write_end, &byte, 1), 1); }
  char take() const {
    char byte = 0;
    EXPECT_EQ(::read(read_end, &byte, 1), 1);
    return byte;
  }
  void closeWriteEnd() {
    if (write_end >= 0) ::close(write_end);
    write_end = -1;
  }
};

/// A waiter watching one pipe's read end, as a stream watches its fd once open.
class ReadWaiterOnAPipe : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(waiter.valid());
    ASSERT_EQ(waiter.watch(pipe.read_end), 0);
  }
  ReadWaiter waiter;
  Pipe pipe;
};

TEST_F(ReadWaiterOnAPipe, NothingDueWaitsOutTheTimeOut) {
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
  EXPECT_EQ(waiter.wait(5).readiness, Readiness::kTimeout);
}

// Edge-triggered: each arrival is announced once, whether or not the bytes before it were read.
TEST_F(ReadWaiterOnAPipe, EachArrivalIsAnnouncedOnce) {
  pipe.put('a');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
  pipe.put('b');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
  EXPECT_EQ(pipe.take(), 'a');
  EXPECT_EQ(pipe.take(), 'b');
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
}

// A reader whose buffer was too small for what had come says so, and is not left asleep beside
// bytes that no new arrival would announce.
TEST_F(ReadWaiterOnAPipe, BytesAReaderLeftBehindEndTheNextWaitAtOnce) {
  pipe.put('a');
  pipe.put('b');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
  EXPECT_EQ(pipe.take(), 'a');  // a one-byte buffer, filled
  waiter.moreMayBeWaiting();
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kMaybeInput);
  EXPECT_EQ(pipe.take(), 'b');
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
}

// Bytes already waiting when the fd is watched (they came before the reader) are announced.
TEST(ReadWaiter, BytesWaitingBeforeTheWatchAreAnnounced) {
  ReadWaiter waiter;
  Pipe pipe;
  pipe.put('e');
  ASSERT_EQ(waiter.watch(pipe.read_end), 0);
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
  EXPECT_EQ(pipe.take(), 'e');
}

// The reader learns first why it was woken (stop, a failed write); the input stays for later.
TEST_F(ReadWaiterOnAPipe, AWakeUpComesBeforeInputAndIsConsumedOnce) {
  pipe.put('b');
  waiter.wake();
  waiter.wake();  // two wake-ups before a wait end one wait
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kWoken);
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kMaybeInput);
  EXPECT_EQ(pipe.take(), 'b');
}

// A wait without a time-out, as an idle port's reader sleeps, ends when another thread wakes it
// (a test that hangs here fails on ctest's time-out).
TEST_F(ReadWaiterOnAPipe, AWakeUpFromAnotherThreadEndsAWaitWithoutLimit) {
  std::thread waker([&] { waiter.wake(); });
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kWoken);
  waker.join();
}

TEST(ReadWaiter, AWakeUpBeforeAnyFdIsWatchedIsKept) {
  ReadWaiter waiter;
  waiter.wake();
  Pipe pipe;
  ASSERT_EQ(waiter.watch(pipe.read_end), 0);
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kWoken);
}

// After a hang-up every wait ends at once, so that the reader's read meets the end (EOF here, EIO
// on a pty) behind the last bytes, however many reads those take.
TEST_F(ReadWaiterOnAPipe, AHangUpEndsEveryWaitUntilTheReaderMeetsTheEnd) {
  pipe.put('c');
  pipe.put('d');
  pipe.closeWriteEnd();
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
  EXPECT_TRUE(waiter.hungUp());
  EXPECT_EQ(pipe.take(), 'c');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kMaybeInput);
  EXPECT_EQ(pipe.take(), 'd');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kMaybeInput);
  char byte = 0;
  EXPECT_EQ(::read(pipe.read_end, &byte, 1), 0);  // the end
}

TEST_F(ReadWaiterOnAPipe, AHangUpWithNothingLeftIsAHangUp) {
  pipe.closeWriteEnd();
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kHangUp);
  EXPECT_TRUE(waiter.hungUp());
}

// A stream that reopens watches its new fd, and only that one: the old one's input or hang-up
// ends no wait (the kernel may hand the new fd the old one's number; here they differ).
TEST(ReadWaiter, WatchingANewFdForgetsTheOldOne) {
  ReadWaiter waiter;
  Pipe old_pipe, new_pipe;
  ASSERT_EQ(waiter.watch(old_pipe.read_end), 0);
  ASSERT_EQ(waiter.watch(new_pipe.read_end), 0);
  old_pipe.put('o');
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
  new_pipe.put('n');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
  EXPECT_EQ(new_pipe.take(), 'n');

  waiter.unwatch(new_pipe.read_end);
  new_pipe.put('x');
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
  EXPECT_EQ(waiter.watch(new_pipe.read_end), 0);
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
}

// What the old fd left (a hang-up, bytes it may still hold) says nothing of the new one.
TEST(ReadWaiter, AReopenedStreamStartsWithoutTheOldFdsHangUpOrLeftovers) {
  ReadWaiter waiter;
  Pipe old_pipe;
  ASSERT_EQ(waiter.watch(old_pipe.read_end), 0);
  old_pipe.closeWriteEnd();
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kHangUp);
  waiter.moreMayBeWaiting();
  waiter.unwatch(old_pipe.read_end);
  Pipe new_pipe;
  ASSERT_EQ(waiter.watch(new_pipe.read_end), 0);
  EXPECT_FALSE(waiter.hungUp());
  EXPECT_EQ(waiter.wait(0).readiness, Readiness::kTimeout);
}

TEST(ReadWaiter, AnFdTheKernelCannotWatchIsRefusedWithItsErrno) {
  ReadWaiter waiter;
  EXPECT_NE(waiter.watch(-1), 0);  // EBADF
  Pipe pipe;
  EXPECT_EQ(waiter.watch(pipe.read_end), 0);
  pipe.put('d');
  EXPECT_EQ(waiter.wait(kNoLimit).readiness, Readiness::kInput);
}

}  // namespace
}  // namespace serial_robot_driver::transport
