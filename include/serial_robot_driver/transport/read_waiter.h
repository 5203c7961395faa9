// How a wakeable stream's reader sleeps: one epoll set holding the stream's fd and an eventfd that
// another thread writes to end the wait at once (ByteStream::wakeRead: stop(), a failed write, work
// for the port's worker). The set is built when the stream opens, so each wait is one epoll_wait:
// a poll() on the same two fds adds both to their wait queues and takes them off again on every
// call. The fd is watched edge-triggered, which spares the kernel a second look at it on the wait
// after each read (bench_wait: the reader's wait in the port's own thread, per frame, against one
// blocking read). An edge announces each arrival once, so the waiter remembers what the reader has
// not used up: input seen beside a wake-up, a read that filled its buffer, a hang-up.
#pragma once

namespace serial_robot_driver::transport {

/// What ended a wait.
enum class Readiness {
  kTimeout,     ///< nothing happened within the time-out (or a signal interrupted the wait)
  kWoken,       ///< wake() was called; input that is waiting too stays for the next wait
  kInput,       ///< bytes arrived on the fd
  kMaybeInput,  ///< bytes may be left (announced beside a wake-up, a filled buffer, a hang-up):
                ///< read to learn, and wait again when there are none
  kHangUp,      ///< the fd hung up or failed with nothing left to read
  kFailed,      ///< the wait itself failed: WaitResult::error holds the errno
};

struct WaitResult {
  Readiness readiness;
  int error = 0;
};

class ReadWaiter {
 public:
  ReadWaiter();
  ~ReadWaiter();
  ReadWaiter(const ReadWaiter&) = delete;
  ReadWaiter& operator=(const ReadWaiter&) = delete;

  /// False if the kernel refused the epoll set or the eventfd: the stream is then not wakeable,
  /// and its reads wait on its fd alone.
  bool valid() const { return epoll_fd_ >= 0 && wake_fd_ >= 0; }
  /// Watches a newly opened fd for input (one at a time). Returns the errno when the kernel
  /// refuses, 0 otherwise (and always 0 for an invalid waiter, which watches nothing).
  int watch(int fd);
  /// Stops watching `fd`: before it is closed, so that a later fd with the same number is new.
  void unwatch(int fd);
  /// Thread-safe; a wait in progress, or the next one, returns kWoken at once.
  void wake();
  /// Waits up to `timeout_ms` (-1: without limit) for input on the watched fd or a wake-up, which
  /// is consumed. The owner calls it from one thread at a time, never beside watch()/unwatch().
  /// Input is reported once per arrival: the reader reads what is there (a non-blocking read) and
  /// calls moreMayBeWaiting() when it did not take it all. Once the fd hung up, every wait reports
  /// kMaybeInput at once, so that the reader's read meets the end (EOF, EIO) after the last bytes.
  WaitResult wait(int timeout_ms);
  /// After a read that filled the reader's buffer (or was interrupted): bytes may still be there
  /// that no new arrival will announce, so the next wait returns kMaybeInput at once.
  void moreMayBeWaiting() { input_pending_ = true; }
  /// The watched fd hung up or failed (until another is watched).
  bool hungUp() const { return hung_up_; }

 private:
  int epoll_fd_;
  int wake_fd_;
  int watched_fd_ = -1;
  bool input_pending_ = false;  ///< announced, not yet handed to the reader, or maybe left unread
  bool hung_up_ = false;  ///< the watched fd hung up or failed: its reader must read to the end
};

}  // namespace serial_robot_driver::transport
