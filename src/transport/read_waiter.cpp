#include "serial_robot_driver/transport/read_waiter.h"

#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>

namespace serial_robot_driver::transport {

ReadWaiter::ReadWaiter()
    : epoll_fd_(::epoll_create1(EPOLL_CLOEXEC)),
      wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  if (!valid()) return;
  epoll_event wake{};
  wake.events = EPOLLIN;
  wake.data.fd = wake_fd_;
  if (::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, wake_fd_, &wake) != 0) {
    ::close(wake_fd_);
    wake_fd_ = -1;
  }
}

ReadWaiter::~ReadWaiter() {
  if (wake_fd_ >= 0) ::close(wake_fd_);
  if (epoll_fd_ >= 0) ::close(epoll_fd_);
}

int ReadWaiter::watch(int fd) {
  if (!valid()) return 0;
  if (watched_fd_ >= 0) unwatch(watched_fd_);
  // Bytes already waiting are announced by the first wait: adding the fd checks it once.
  epoll_event input{};
  input.events = EPOLLIN | EPOLLET;
  input.data.fd = fd;
  if (::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &input) != 0) return errno;
  watched_fd_ = fd;
  return 0;
}

void ReadWaiter::unwatch(int fd) {
  if (!valid() || fd != watched_fd_) return;
  (void)::epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  watched_fd_ = -1;
  input_pending_ = false;
  hung_up_ = false;
}

void ReadWaiter::wake() {
  if (wake_fd_ < 0) return;
  const uint64_t one = 1;
  if (::write(wake_fd_, &one, sizeof(one)) < 0) { /* the count is already non-zero: still woken */
  }
}

WaitResult ReadWaiter::wait(int timeout_ms) {
  if (input_pending_ || hung_up_) {
    input_pending_ = false;
    return {Readiness::kMaybeInput};
  }
  epoll_event events[2];
  const int count = ::epoll_wait(epoll_fd_, events, 2, timeout_ms);
  if (count < 0) {
    return errno == EINTR ? WaitResult{Readiness::kTimeout} : WaitResult{Readiness::kFailed, errno};
  }
  bool woken = false;
  Readiness readiness = Readiness::kTimeout;
  for (int i = 0; i < count; ++i) {
    if (events[i].data.fd == wake_fd_) {
      uint64_t wakes = 0;
      if (::read(wake_fd_, &wakes, sizeof(wakes)) < 0) { /* already consumed: still woken */
      }
      woken = true;
      continue;
    }
    if (events[i].events & (EPOLLHUP | EPOLLERR)) hung_up_ = true;
    readiness = (events[i].events & EPOLLIN) ? Readiness::kInput : Readiness::kHangUp;
  }
  if (woken) {
    // The caller checks why it was woken first; the input this edge announced is its next wait's.
    input_pending_ = readiness != Readiness::kTimeout;
    return {Readiness::kWoken};
  }
  return {readiness};
}

}  // namespace serial_robot_driver::transport
