#include "serial_robot_driver/sim/robot_sim.h"

#include <poll.h>
#include <pthread.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "robot_sim_hosted.h"
#include "robot_sim_line.h"
#include "robot_sim_plug.h"
#include "robot_sim_port.h"
#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/core/scheduler_slice.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"

namespace serial_robot_driver::sim {

using detail::Port;
using detail::setNonBlocking;
using protocol::FrameFamily;

namespace {
/// Reads of one port per wake-up, so a chatty host cannot starve the others.
constexpr int kReadsPerWake = 16;
/// The longest the loop sleeps without an event due.
constexpr auto kIdleWake = std::chrono::milliseconds(100);
}  // namespace

struct RobotSim::PollSet {
  std::vector<pollfd> fds;
  std::vector<Port*> ports;  ///< by index in fds (nullptr for the wake pipe)
};

RobotSim::RobotSim(SimOptions options)
    : options_(std::move(options)),
      line_(std::make_unique<detail::Line>(options_, counters_)),
      hosted_(std::make_unique<detail::HostedDevices>(options_, counters_, *line_)),
      plug_faults_(std::make_unique<detail::PlugFaults>(
          options_, counters_, [this](const std::string& text) { event(text); })) {}

RobotSim::~RobotSim() {
  stop();
  for (auto& port : ports_) {
    if (port->drain_probe_fd >= 0) ::close(port->drain_probe_fd);
  }
  for (int fd : wake_pipe_) {
    if (fd >= 0) ::close(fd);
  }
}

void RobotSim::event(const std::string& text) const {
  if (options_.on_event) options_.on_event(text);
}

void RobotSim::checkSomethingHosted() const {
  const auto& modules = registeredSimDevices();
  if (std::none_of(modules.begin(), modules.end(),
                   [&](const SimDeviceModule* module) { return options_.hosts(module->name); })) {
    throw std::invalid_argument("robot_sim: every device is disabled");
  }
}

void RobotSim::start() {
  if (running_ || thread_.joinable()) return;
  checkSomethingHosted();
  std::lock_guard<std::mutex> lock(mutex_);
  const TimePoint now = Clock::now();
  started_at_ = now;
  next_stats_write_ = now + fromSeconds(options_.stats_period_s);
  hosted_->start(now);
  // The ports named as the driver names its devices (the device set), in the devices' order;
  // devices whose effective links are equal share one pty.
  for (detail::Hosted& hosted : hosted_->all()) {
    hosted.port = portFor(hosted.port_link, hosted.name);
  }
  for (auto& port : ports_) openPort(port.get(), now);

  if (::pipe(wake_pipe_) != 0) throw std::runtime_error("robot_sim: pipe() failed");
  setNonBlocking(wake_pipe_[0]);
  stop_requested_ = false;
  running_ = true;
  thread_ = std::thread(&RobotSim::run, this);
}

Port* RobotSim::portFor(const std::string& link, const std::string& device_name) {
  for (auto& port : ports_) {
    if (port->link == link) {
      port->device_names.push_back(device_name);
      return port.get();
    }
  }
  auto port = std::make_unique<Port>();
  Port* raw = port.get();
  // The framer calls back into the devices on this port; a frame for a device that lives on
  // another port (or is not hosted) is only counted.
  port->framer = std::make_unique<protocol::StreamFramer>(
      core::simulatorFramerFor(core::registeredDevices()),
      [this, raw](const FrameFamily& family, const uint8_t* data, std::size_t size) {
        // Paced: the request arrived when its last bit was through the line, not when this
        // thread woke up to feed it.
        const TimePoint at = raw->rx_frame_end == TimePoint{} ? Clock::now() : raw->rx_frame_end;
        if (!hosted_->deliver(raw, family, data, size, at)) ++counters_.frames_for_absent_device;
      });
  port->link = link;
  port->device_names.push_back(device_name);
  port->rng.seed(options_.faults.seed + 100 + static_cast<uint32_t>(ports_.size()));
  ports_.push_back(std::move(port));
  return raw;
}

void RobotSim::openPort(Port* port, TimePoint now) {
  detail::openEndpoint(port);
  plug_faults_->schedule(port, now);
  line_->scheduleGarbage(port, now);
}

void RobotSim::stop() {
  if (!thread_.joinable()) return;
  stop_requested_ = true;
  const uint8_t wake = 1;
  [[maybe_unused]] const ssize_t ignored = ::write(wake_pipe_[1], &wake, 1);
  thread_.join();
  running_ = false;
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& port : ports_) line_->flush(port.get());  // a last attempt, never blocking
  writeStatsFile();
}

void RobotSim::step(TimePoint now) {
  // --pace-baud: what the host wrote reaches the devices once its last bit is through the line.
  for (auto& port : ports_) line_->deliverArrived(port.get(), now);
  hosted_->tick(now);
  for (auto& owned : ports_) {
    Port* port = owned.get();
    plug_faults_->step(port, now);
    line_->injectGarbage(port, now);
    if (port->plugged) line_->flush(port);
  }
  if (now >= next_stats_write_) {
    writeStatsFile();
    next_stats_write_ = now + fromSeconds(options_.stats_period_s);
  }
}

void RobotSim::run() {
  // Wake up on time: the kernel's default 50 us of timer slack would add to every paced byte and
  // every answer latency.
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  // Answer as the boards' microcontrollers do, at once: with the shortest fair-scheduler turn a
  // busy machine (a CI run, the benchmark's hogs) delays this thread by a fraction of a ms, not
  // by a CPU hog's whole turn (core/scheduler_slice.h). Tests that compare the node's odometry,
  // timed at its writes, with the simulated wheels, timed at this thread's reads, rely on it.
  core::requestSchedulerSlice(core::kMinSchedulerSliceUs);
  ::pthread_setname_np(::pthread_self(), "robot_sim");  // as ps -L, top -H and perf show it
  PollSet poll;
  // The wait to the next event in ns (ppoll): a poll timeout in whole ms would round every paced
  // byte, answer latency and timer up to the next ms.
  Clock::duration wait{0};
  while (!stop_requested_) {
    preparePoll(&poll);
    const auto wait_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
    const timespec timeout{static_cast<time_t>(wait_ns / 1000000000),
                           static_cast<long>(wait_ns % 1000000000)};  // NOLINT: timespec's type
    ::ppoll(poll.fds.data(), poll.fds.size(), &timeout, nullptr);
    if (stop_requested_) break;

    std::lock_guard<std::mutex> lock(mutex_);
    readPorts(poll);
    const TimePoint now = Clock::now();
    step(now);
    wait = std::max(Clock::duration::zero(), nextWakeUp(now) - Clock::now());
  }
}

void RobotSim::preparePoll(PollSet* poll) {
  std::lock_guard<std::mutex> lock(mutex_);
  poll->fds.clear();
  poll->ports.clear();
  poll->fds.push_back(pollfd{wake_pipe_[0], POLLIN, 0});
  poll->ports.push_back(nullptr);
  for (auto& port : ports_) {
    if (!port->plugged || !port->isOpen()) continue;
    if (port->tcp && port->tcp->clientFd() < 0) {  // a TCP port without a client: wait for one
      poll->fds.push_back(pollfd{port->tcp->listenFd(), POLLIN, 0});
      poll->ports.push_back(port.get());
      continue;
    }
    if (port->dataFd() < 0) continue;
    // Paced: no POLLOUT while the line is busy, or poll would return at once until it frees.
    const bool may_send = !port->backlog.empty() && (options_.pace_baud == 0 ||
                                                     Clock::now() >= line_->nextSendAt(port.get()));
    const short events = may_send ? (POLLIN | POLLOUT) : POLLIN;
    poll->fds.push_back(pollfd{port->dataFd(), events, 0});
    poll->ports.push_back(port.get());
  }
}

void RobotSim::readPorts(const PollSet& poll) {
  std::array<uint8_t, 4096> buffer;
  const TimePoint read_at = Clock::now();
  for (std::size_t i = 1; i < poll.fds.size(); ++i) {
    Port* port = poll.ports[i];
    if ((poll.fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0 || !port->isOpen()) continue;
    const int fd = port->dataFd();
    if (port->tcp && poll.fds[i].fd == port->tcp->listenFd()) {
      attachClient(port);
      continue;
    }
    if (fd < 0) continue;
    for (int reads = 0; reads < kReadsPerWake; ++reads) {
      const ssize_t n = ::read(fd, buffer.data(), buffer.size());
      if (port->tcp && (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR))) {
        detachClient(port);  // the host closed its connection
        break;
      }
      if (n <= 0) break;
      counters_.bytes_received += static_cast<uint64_t>(n);
      line_->receive(port, buffer.data(), static_cast<std::size_t>(n), read_at);
    }
  }
}

void RobotSim::attachClient(Port* port) {
  if (!port->tcp->accept()) return;
  // A new connection starts with fresh bytes, as a serial line read from now on.
  detail::discardBacklog(port, counters_);
  port->framer->reset();
  event("robot_sim: " + detail::joinNames(port->device_names) + ": a client connected on " +
        port->slave_path);
}

void RobotSim::detachClient(Port* port) {
  port->tcp->dropClient();
  detail::discardBacklog(port, counters_);
  port->framer->reset();
  event("robot_sim: " + detail::joinNames(port->device_names) + ": the client on " +
        port->slave_path + " disconnected");
}

TimePoint RobotSim::nextWakeUp(TimePoint now) const {
  TimePoint next = std::min({now + kIdleWake, hosted_->nextEvent(), next_stats_write_});
  for (const auto& port : ports_) {
    next = std::min({next, plug_faults_->nextEvent(*port, now), line_->nextEvent(*port)});
  }
  return next;
}

SimStats RobotSim::snapshotLocked() const {
  SimStats stats = counters_;
  for (const auto& port : ports_) stats.framer.add(port->framer->stats());
  hosted_->addStats(&stats);
  stats.uptime_s = toSeconds(Clock::now() - started_at_);
  return stats;
}

SimStats RobotSim::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshotLocked();
}

std::vector<SimPort> RobotSim::ports() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SimPort> result;
  for (const auto& port : ports_) {
    result.push_back(SimPort{port->device_names, port->link, port->slave_path, port->plugged});
  }
  return result;
}

void RobotSim::writeStatsFile() const {
  if (options_.stats_file.empty()) return;
  const std::string temporary = options_.stats_file + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    if (!out) return;
    out << formatStats(snapshotLocked());
    if (!out) return;
  }
  std::rename(temporary.c_str(), options_.stats_file.c_str());
}

}  // namespace serial_robot_driver::sim
