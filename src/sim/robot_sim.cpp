#include "serial_robot_driver/sim/robot_sim.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <deque>
#include <fstream>
#include <iomanip>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "robot_sim_port.h"
#include "serial_robot_driver/device/device_module.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"
#include "serial_robot_driver/transport/byte_stream.h"

namespace serial_robot_driver::sim {

using detail::kMaxBacklogBytes;
using detail::setNonBlocking;
using protocol::FrameFamily;

namespace {

/// How long an unplug waits for the host to read what was already sent.
constexpr auto kDrainTimeout = std::chrono::milliseconds(250);
constexpr std::size_t kMaxGarbageBurst = 24;
/// With --pace-baud, a long frame goes into the pty in pieces of what the line carries in this
/// much time: a finer slice would only wake the simulator more often. A shorter frame goes in
/// whole once its last bit is through the line, as a UART reader would see it complete.
constexpr auto kPaceSlice = std::chrono::milliseconds(2);

/// Index of the checksum byte a corruption flips (the kind says where its checksum is).
std::size_t checksumIndex(const OutputKind& kind, std::size_t size) {
  return size >= kind.checksum_from_end ? size - kind.checksum_from_end : size - 1;
}

}  // namespace

RobotSim::RobotSim(SimOptions options) : options_(std::move(options)) {}

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

void RobotSim::start() {
  if (running_ || thread_.joinable()) return;
  const auto& modules = registeredSimDevices();
  if (std::none_of(modules.begin(), modules.end(),
                   [&](const SimDeviceModule* module) { return options_.hosts(module->name); })) {
    throw std::invalid_argument("robot_sim: every device is disabled");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const TimePoint now = Clock::now();
  started_at_ = now;
  next_stats_write_ = now + fromSeconds(options_.stats_period_s);
  const FaultOptions& faults = options_.faults;
  startHosted(now);

  // Devices whose effective links are equal share one pty.
  const auto portFor = [&](const std::string& link, const std::string& name) -> Port* {
    for (auto& port : ports_) {
      if (port->link == link) {
        port->device_names.push_back(name);
        return port.get();
      }
    }
    auto port = std::make_unique<Port>();
    Port* raw = port.get();
    // The framer calls back into the devices on this port; a frame for a device that lives on
    // another port (or is not hosted) is only counted.
    port->framer = std::make_unique<protocol::StreamFramer>(
        device::simulatorFramerFor(device::registeredDevices()),
        [this, raw](const FrameFamily& family, const uint8_t* data, std::size_t size) {
          // Paced: the request arrived when its last bit was through the line, not when this
          // thread woke up to feed it.
          const TimePoint at = rx_frame_end_ == TimePoint{} ? Clock::now() : rx_frame_end_;
          if (!deliverToHosted(raw, family, data, size, at)) ++counters_.frames_for_absent_device;
        });
    port->link = link;
    port->device_names.push_back(name);
    port->rng.seed(faults.seed + 100 + static_cast<uint32_t>(ports_.size()));
    ports_.push_back(std::move(port));
    return raw;
  };
  // The ports named as the driver names its devices (the device set), in the devices' order.
  for (Hosted& hosted : hosted_) hosted.port = portFor(hosted.port_link, hosted.name);

  for (auto& port : ports_) {
    port->pty = std::make_unique<PseudoTerminal>(port->link);
    port->slave_path = port->pty->slavePath();
    setNonBlocking(port->pty->masterFd());
    if (faults.unplug_every_s > 0) port->next_unplug = now + fromSeconds(faults.unplug_every_s);
    if (faults.garbage_rate_hz > 0) {
      std::exponential_distribution<double> gap(faults.garbage_rate_hz);
      port->next_garbage = now + fromSeconds(gap(port->rng));
    }
  }

  if (::pipe(wake_pipe_) != 0) throw std::runtime_error("robot_sim: pipe() failed");
  setNonBlocking(wake_pipe_[0]);
  stop_requested_ = false;
  running_ = true;
  thread_ = std::thread(&RobotSim::run, this);
}

void RobotSim::stop() {
  if (!thread_.joinable()) return;
  stop_requested_ = true;
  const uint8_t wake = 1;
  [[maybe_unused]] const ssize_t ignored = ::write(wake_pipe_[1], &wake, 1);
  thread_.join();
  running_ = false;
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& port : ports_) flush(port.get());  // a last attempt, never blocking
  writeStatsFile();
}

void RobotSim::send(Port* port, Outgoing frame) {
  SendCounters& counters = countersOf(frame.kind);
  if (port == nullptr || !port->plugged || port->draining || frame.bytes.empty()) {
    ++counters.discarded;
    return;
  }
  const FaultOptions& faults = options_.faults;
  std::uniform_real_distribution<double> chance(0.0, 1.0);
  bool damaged = false;
  std::vector<uint8_t>& bytes = frame.bytes;
  if (frame.garble_or_suppress_rate > 0 && chance(port->rng) < frame.garble_or_suppress_rate) {
    if (chance(port->rng) < 0.5) {
      ++counters.suppressed;
      return;
    }
    const std::size_t index =
        std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(port->rng);
    bytes[index] ^= static_cast<uint8_t>(std::uniform_int_distribution<int>(1, 255)(port->rng));
    damaged = true;
  }
  if (faults.corrupt_rate > 0 && chance(port->rng) < faults.corrupt_rate) {
    bytes[checksumIndex(*frame.kind, bytes.size())] ^= 0xFF;
    damaged = true;
  }
  if (faults.drop_rate > 0 && chance(port->rng) < faults.drop_rate) {
    const std::size_t index =
        std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(port->rng);
    bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(index));
    damaged = true;
  }
  if (port->backlog_bytes + bytes.size() > kMaxBacklogBytes) {
    ++counters.discarded;
    return;
  }
  port->backlog_bytes += bytes.size();
  const TimePoint ready_at = frame.ready_at == TimePoint{} ? Clock::now() : frame.ready_at;
  port->backlog.push_back(
      Port::PendingWrite{std::move(bytes), 0, true, frame.kind, damaged, ready_at});
  flush(port);
}

Clock::duration RobotSim::lineTime(std::size_t bytes) const {
  return std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(10.0 * static_cast<double>(bytes) / options_.pace_baud));
}

TimePoint RobotSim::nextSendAt(const Port* port) const {
  if (port->backlog.empty()) return TimePoint::max();
  const Port::PendingWrite& pending = port->backlog.front();
  const TimePoint line_start = std::max(port->tx_line_free, pending.ready_at);
  const std::size_t slice_bytes = std::max<std::size_t>(
      1, static_cast<std::size_t>(options_.pace_baud / 10.0 *
                                  std::chrono::duration<double>(kPaceSlice).count()));
  return line_start + lineTime(std::min(pending.bytes.size() - pending.offset, slice_bytes));
}

void RobotSim::flush(Port* port) {
  if (!port->pty || !port->pty->isOpen()) return;
  const int fd = port->pty->masterFd();
  const bool paced = options_.pace_baud > 0;
  const TimePoint now = paced ? Clock::now() : TimePoint{};
  while (!port->backlog.empty()) {
    Port::PendingWrite& pending = port->backlog.front();
    std::size_t remaining = pending.bytes.size() - pending.offset;
    TimePoint line_start{};
    if (paced) {
      // Paced: once the next slice (or the whole of a short frame) is through, the bytes whose
      // last bit is through the line by now (the line carries a frame from when it is ready,
      // after what it carried before). A late wake-up delivers late but never stretches the
      // line: tx_line_free follows the line's own clock, not this thread's.
      if (now < nextSendAt(port)) return;
      line_start = std::max(port->tx_line_free, pending.ready_at);
      const auto through = static_cast<std::size_t>((now - line_start) / lineTime(1));
      remaining = std::min(remaining, through);
      if (remaining == 0) return;
    }
    const ssize_t written = ::write(fd, pending.bytes.data() + pending.offset, remaining);
    if (written < 0) {
      if (errno == EINTR) continue;
      return;  // EAGAIN: the host is not reading right now; retry when poll says writable
    }
    if (paced) port->tx_line_free = line_start + lineTime(static_cast<std::size_t>(written));
    counters_.bytes_sent += static_cast<uint64_t>(written);
    port->backlog_bytes -= static_cast<std::size_t>(written);
    pending.offset += static_cast<std::size_t>(written);
    if (pending.offset < pending.bytes.size()) continue;
    if (pending.is_frame) {
      SendCounters& counters = countersOf(pending.kind);
      ++(pending.damaged ? counters.damaged : counters.intact);
    }
    port->backlog.pop_front();
  }
}

void RobotSim::step(TimePoint now) {
  // --pace-baud: what the host wrote reaches the devices once its last bit is through the line.
  for (auto& owned : ports_) {
    Port* port = owned.get();
    while (!port->rx_in_flight.empty() && port->rx_in_flight.front().first <= now) {
      const std::vector<uint8_t> bytes = std::move(port->rx_in_flight.front().second);
      rx_frame_end_ = port->rx_in_flight.front().first;
      port->rx_in_flight.pop_front();
      port->framer->feed(bytes.data(), bytes.size());
      rx_frame_end_ = TimePoint{};
    }
  }
  // Every device ticks before any sends: what one writes into the world (the chassis it moves)
  // reaches a later one in the same step.
  for (Hosted& hosted : hosted_) hosted.device->tick(now, world_, &hosted.outbox);
  for (Hosted& hosted : hosted_) sendAll(&hosted);

  const FaultOptions& faults = options_.faults;
  for (auto& owned : ports_) {
    Port* port = owned.get();
    if (port->plugged && !port->draining && now >= port->next_unplug) {
      // Let the host read what is already in flight, so "sent" means "could be received".
      port->draining = true;
      port->next_unplug = TimePoint::max();  // replug() schedules the next one
      port->drain_deadline = now + kDrainTimeout;
      port->drain_probe_fd = ::open(port->slave_path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    }
    if (port->draining) {
      int unread = 0;
      const bool probe_ok =
          port->drain_probe_fd >= 0 && ::ioctl(port->drain_probe_fd, FIONREAD, &unread) == 0;
      if ((port->backlog.empty() && probe_ok && unread == 0) || now >= port->drain_deadline) {
        unplug(port, now);
      }
    }
    if (!port->plugged && now >= port->replug_at) replug(port, now);

    if (now >= port->next_garbage) {
      std::exponential_distribution<double> gap(faults.garbage_rate_hz);
      port->next_garbage = now + fromSeconds(gap(port->rng));
      if (port->plugged && !port->draining) {
        const std::size_t length =
            std::uniform_int_distribution<std::size_t>(1, kMaxGarbageBurst)(port->rng);
        Port::PendingWrite junk;
        junk.is_frame = false;
        junk.ready_at = now;
        for (std::size_t i = 0; i < length; ++i) {
          junk.bytes.push_back(
              static_cast<uint8_t>(std::uniform_int_distribution<int>(0, 255)(port->rng)));
        }
        if (port->backlog_bytes + length <= kMaxBacklogBytes) {
          port->backlog_bytes += length;
          port->backlog.push_back(std::move(junk));
          ++counters_.garbage_bursts;
          counters_.garbage_bytes += length;
        }
      }
    }
    if (port->plugged) flush(port);
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
  std::vector<pollfd> fds;
  std::vector<Port*> fd_ports;
  std::array<uint8_t, 4096> buffer{};
  // The wait to the next event in ns (ppoll): a poll timeout in whole ms would round every paced
  // byte, answer latency and timer up to the next ms.
  Clock::duration wait{0};
  while (!stop_requested_) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      fds.clear();
      fd_ports.clear();
      fds.push_back(pollfd{wake_pipe_[0], POLLIN, 0});
      fd_ports.push_back(nullptr);
      for (auto& port : ports_) {
        if (!port->plugged || !port->pty) continue;
        // Paced: no POLLOUT while the line is busy, or poll would return at once until it frees.
        const bool may_send = !port->backlog.empty() &&
                              (options_.pace_baud == 0 || Clock::now() >= nextSendAt(port.get()));
        const short events = may_send ? (POLLIN | POLLOUT) : POLLIN;
        fds.push_back(pollfd{port->pty->masterFd(), events, 0});
        fd_ports.push_back(port.get());
      }
    }
    const auto wait_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count();
    const timespec timeout{static_cast<time_t>(wait_ns / 1000000000),
                           static_cast<long>(wait_ns % 1000000000)};  // NOLINT: timespec's type
    ::ppoll(fds.data(), fds.size(), &timeout, nullptr);
    if (stop_requested_) break;

    std::lock_guard<std::mutex> lock(mutex_);
    const TimePoint read_at = Clock::now();
    for (std::size_t i = 1; i < fds.size(); ++i) {
      Port* port = fd_ports[i];
      if ((fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0 || !port->pty) continue;
      const int fd = port->pty->masterFd();
      for (int reads = 0; reads < 16; ++reads) {
        const ssize_t n = ::read(fd, buffer.data(), buffer.size());
        if (n <= 0) break;
        counters_.bytes_received += static_cast<uint64_t>(n);
        if (options_.pace_baud > 0) {
          port->rx_line_free =
              std::max(port->rx_line_free, read_at) + lineTime(static_cast<std::size_t>(n));
          port->rx_in_flight.emplace_back(port->rx_line_free,
                                          std::vector<uint8_t>(buffer.data(), buffer.data() + n));
        } else {
          port->framer->feed(buffer.data(), static_cast<std::size_t>(n));
        }
      }
    }
    const TimePoint now = Clock::now();
    step(now);

    TimePoint next = now + std::chrono::milliseconds(100);
    for (const Hosted& hosted : hosted_) next = std::min(next, hosted.device->nextEvent());
    next = std::min(next, next_stats_write_);
    for (auto& port : ports_) {
      next = std::min({next, port->next_unplug, port->replug_at, port->next_garbage});
      if (port->draining) next = std::min(next, now + std::chrono::milliseconds(5));
      if (options_.pace_baud > 0) next = std::min(next, nextSendAt(port.get()));
      if (!port->rx_in_flight.empty()) next = std::min(next, port->rx_in_flight.front().first);
    }
    wait = std::max(Clock::duration::zero(), next - Clock::now());
  }
}

SimStats RobotSim::snapshotLocked() const {
  SimStats stats = counters_;
  for (const auto& port : ports_) stats.framer.add(port->framer->stats());
  for (const SimDeviceModule* module : registeredSimDevices()) {
    PortCounters seen;
    seen.all_ports = stats.framer;
    const auto hosted = std::find_if(hosted_.begin(), hosted_.end(),
                                     [&](const Hosted& h) { return h.name == module->name; });
    if (hosted != hosted_.end()) {
      seen.own_port = hosted->port->framer->stats();
      stats.devices.push_back(hosted->device->stats(seen));
    } else if (module->left_out_stats != nullptr) {
      stats.devices.push_back(module->left_out_stats(seen));  // its keys, at zero
    }
  }
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
