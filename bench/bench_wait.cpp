// bench_wait: what a thread spends to wait for its next event, driver_node's way against the
// floor's (bench/floor_node.cpp), per wake-up, in the thread's own CPU clock (user + kernel).
//
//  reader  a 130-byte frame written to a pty at 100 Hz (telemetry's size and rate). driver_node's
//          port reader: transport::SerialPort::read, an epoll_wait() on the set its ReadWaiter
//          keeps of the port and an eventfd (so that stop() or a failed write can end the wait),
//          without a time-out when nothing else is due (a second row: with one), then a
//          non-blocking read(). The floor: one blocking read() on the pty. A third row waits as the
//          reader did before ReadWaiter: a poll() on both fds with the 5 s time-out it then had.
//  loop    a 50 Hz deadline. driver_node's base loop: its core::LoopWake (a semaphore) waited on
//          until the deadline through core::steadyLoopClock, so that an e-stop, a command or stop()
//          can wake it. The floor: clock_nanosleep(TIMER_ABSTIME). A third row waits on a
//          condition variable instead, as the loop did before LoopWake.
//
// The two ways take turns within each round, which goes first alternating, so that the machine's
// drift weighs on both; each round's ratio is printed beside the means. Numbers only: nothing is
// asserted. Built with -DSRD_BUILD_BENCHMARKS=ON; run it with no arguments, or --help.
#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "serial_robot_driver/core/loop_clock.h"
#include "serial_robot_driver/core/loop_wake.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/transport/serial_port.h"

namespace {

using namespace serial_robot_driver;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kFrameBytes = 130;
constexpr double kFrameRateHz = 100.0;
constexpr auto kLoopPeriod = std::chrono::milliseconds(20);

double threadCpuSeconds() {
  timespec now{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return now.tv_sec + now.tv_nsec * 1e-9;
}

/// CPU seconds per wake-up of one waiting thread over one window.
struct Window {
  double cpu_seconds = 0;
  std::size_t wakes = 0;
  double perWakeUs() const { return wakes ? cpu_seconds / wakes * 1e6 : 0.0; }
};

/// Runs `wait_once` on a thread of its own until `stop` is set; its CPU and the wake-ups it
/// counted (wait_once returns true for a wake-up with work: a read with bytes, a tick).
Window measureThread(const std::function<bool()>& wait_once, const std::atomic<bool>& stop) {
  Window window;
  std::thread waiter([&] {
    const double start = threadCpuSeconds();
    while (!stop) {
      if (wait_once()) ++window.wakes;
    }
    window.cpu_seconds = threadCpuSeconds() - start;
  });
  waiter.join();
  return window;
}

/// The reader's window: a writer thread feeds `pty` a frame every 10 ms while `read_once` reads.
/// `unblock` ends a read still waiting once the window is over.
Window readerWindow(sim::PseudoTerminal& pty, double seconds,
                    const std::function<bool()>& read_once, const std::function<void()>& unblock) {
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    const std::vector<uint8_t> frame(kFrameBytes, 0x55);
    const Clock::time_point start = Clock::now();
    for (std::size_t k = 0; Clock::now() - start < std::chrono::duration<double>(seconds); ++k) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(k / kFrameRateHz)));
      pty.write(frame.data(), frame.size());
    }
    stop = true;
    unblock();
  });
  const Window window = measureThread(read_once, stop);
  writer.join();
  return window;
}

/// driver_node's way: SerialPort::read as its port reader calls it, with a time-out in ms (-1:
/// none, when nothing else is due; the port is wakeable).
template <int kTimeoutMs>
Window nodeReader(double seconds) {
  sim::PseudoTerminal pty;
  transport::SerialPort port({pty.slavePath(), 115200});
  port.open();
  std::vector<uint8_t> buffer(4096);
  return readerWindow(
      pty, seconds, [&] { return port.read(buffer.data(), buffer.size(), kTimeoutMs) > 0; },
      [&] { port.wakeRead(); });
}

/// The pty's client end, raw, opened with `flags` beside O_RDWR.
int openRaw(const sim::PseudoTerminal& pty, int flags) {
  const int fd = ::open(pty.slavePath().c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC | flags);
  if (fd < 0) throw std::runtime_error("cannot open " + pty.slavePath());
  termios raw{};
  ::tcgetattr(fd, &raw);
  ::cfmakeraw(&raw);
  ::tcsetattr(fd, TCSANOW, &raw);
  return fd;
}

/// driver_node's reader before ReadWaiter: a poll() on the non-blocking port and an eventfd, then a
/// read().
Window pollingReader(double seconds) {
  sim::PseudoTerminal pty;
  const int fd = openRaw(pty, O_NONBLOCK);
  const int wake_fd = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd < 0) throw std::runtime_error("cannot make an eventfd");
  std::vector<uint8_t> buffer(4096);
  const Window window = readerWindow(
      pty, seconds,
      [&] {
        pollfd waiters[2] = {{fd, POLLIN, 0}, {wake_fd, POLLIN, 0}};
        if (::poll(waiters, 2, 5000) <= 0 || !(waiters[0].revents & POLLIN)) return false;
        return ::read(fd, buffer.data(), buffer.size()) > 0;
      },
      [&] {
        const uint64_t one = 1;
        if (::write(wake_fd, &one, sizeof(one)) < 0) {
        }
      });
  ::close(wake_fd);
  ::close(fd);
  return window;
}

/// The floor's way: a blocking read() on the raw pty.
Window floorReader(double seconds) {
  sim::PseudoTerminal pty;
  const int fd = openRaw(pty, 0);
  std::vector<uint8_t> buffer(4096);
  const uint8_t last_byte = 0;
  const Window window = readerWindow(
      pty, seconds, [&] { return ::read(fd, buffer.data(), buffer.size()) > 0; },
      [&] { pty.write(&last_byte, 1); });  // one more byte ends the blocked read
  ::close(fd);
  return window;
}

/// driver_node's way: the base loop's wait on its LoopWake (or, as it was, on a condition variable:
/// `Wake` = std::condition_variable) until the next deadline.
template <typename Wake>
Window loopWaitingOn(double seconds) {
  const auto clock = core::steadyLoopClock();
  std::mutex mutex;
  Wake wake;
  std::atomic<bool> stop{false};
  const Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(seconds));
  Clock::time_point deadline = clock->now() + kLoopPeriod;
  std::unique_lock<std::mutex> lock(mutex, std::defer_lock);
  return measureThread(
      [&] {
        lock.lock();
        while (clock->now() < deadline) clock->waitUntil(lock, wake, deadline);
        lock.unlock();
        deadline += kLoopPeriod;
        if (Clock::now() >= end) stop = true;
        return true;
      },
      stop);
}

/// The floor's way: clock_nanosleep on absolute deadlines.
Window floorLoop(double seconds) {
  std::atomic<bool> stop{false};
  const Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(seconds));
  timespec deadline{};
  ::clock_gettime(CLOCK_MONOTONIC, &deadline);
  return measureThread(
      [&] {
        deadline.tv_nsec += std::chrono::nanoseconds(kLoopPeriod).count();
        if (deadline.tv_nsec >= 1000000000) {
          deadline.tv_nsec -= 1000000000;
          ++deadline.tv_sec;
        }
        ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr);
        if (Clock::now() >= end) stop = true;
        return true;
      },
      stop);
}

/// One comparison: its rounds' windows, the floor's and driver_node's.
struct Comparison {
  const char* what;
  Window (*floor)(double);
  Window (*node)(double);
  std::vector<Window> floor_windows, node_windows;
};

double meanPerWakeUs(const std::vector<Window>& windows) {
  Window total;
  for (const Window& w : windows) {
    total.cpu_seconds += w.cpu_seconds;
    total.wakes += w.wakes;
  }
  return total.perWakeUs();
}

void printTable(const std::vector<Comparison>& comparisons, int rounds, double seconds) {
  std::printf(
      "\n| wait | floor's way, CPU per wake-up | driver_node's way | node - floor | node / floor "
      "| node / floor, each round |\n|---|---|---|---|---|---|\n");
  for (const Comparison& c : comparisons) {
    const double floor_us = meanPerWakeUs(c.floor_windows);
    const double node_us = meanPerWakeUs(c.node_windows);
    std::string each_round;
    for (std::size_t r = 0; r < c.floor_windows.size(); ++r) {
      if (!each_round.empty()) each_round += ", ";
      char cell[32];
      std::snprintf(cell, sizeof(cell), "%.2fx",
                    c.node_windows[r].perWakeUs() / c.floor_windows[r].perWakeUs());
      each_round += cell;
    }
    std::printf("| %s | %.1f us | %.1f us | %+.1f us | %.2fx | %s |\n", c.what, floor_us, node_us,
                node_us - floor_us, node_us / floor_us, each_round.c_str());
  }
  std::printf("\n%d round(s) of %.0f s per way; CPU from each waiting thread's own clock.\n", rounds,
              seconds);
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 6;
  double seconds = 5.0;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--rounds" && i + 1 < argc) {
      rounds = std::max(1, std::atoi(argv[++i]));
    } else if (flag == "--seconds" && i + 1 < argc) {
      seconds = std::max(1.0, std::atof(argv[++i]));
    } else {
      std::printf(
          "usage: bench_wait [--rounds N (6)] [--seconds S (5)]\n"
          "CPU per wake-up of driver_node's port reader and base loop waiting their way, against "
          "the floor's (blocking read, clock_nanosleep), alternating in each round.\n");
      return flag == "--help" ? 0 : 2;
    }
  }
  std::vector<Comparison> comparisons{
      {"port reader, 130 B at 100 Hz on a pty (epoll_wait + read vs blocking read)", floorReader,
       nodeReader<-1>, {}, {}},
      {"port reader, the same with a 5 s time-out (something due: a servo poll, a partial frame)",
       floorReader, nodeReader<5000>, {}, {}},
      {"port reader, poll on the port and an eventfd + read (driver_node's before ReadWaiter)",
       floorReader, pollingReader, {}, {}},
      {"50 Hz loop (LoopWake until the deadline vs clock_nanosleep)", floorLoop,
       loopWaitingOn<core::LoopWake>, {}, {}},
      {"50 Hz loop, a condition variable (driver_node's loop before LoopWake)", floorLoop,
       loopWaitingOn<std::condition_variable>, {}, {}},
  };
  try {
    for (int round = 0; round < rounds; ++round) {
      for (Comparison& c : comparisons) {
        const bool floor_first = round % 2 == 0;
        const Window first = floor_first ? c.floor(seconds) : c.node(seconds);
        const Window second = floor_first ? c.node(seconds) : c.floor(seconds);
        c.floor_windows.push_back(floor_first ? first : second);
        c.node_windows.push_back(floor_first ? second : first);
      }
      std::fprintf(stderr, "bench_wait: round %d of %d done\n", round + 1, rounds);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_wait: %s\n", e.what());
    return 1;
  }
  printTable(comparisons, rounds, seconds);
  return 0;
}
