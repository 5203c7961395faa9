#include "serial_robot_driver/sim/robot_sim.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <iomanip>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "serial_robot_driver/transport/byte_stream.h"
#include "serial_robot_driver/sim/pseudo_terminal.h"

namespace serial_robot_driver::sim {

using protocol::FrameFamily;

namespace {

/// Bytes queued for a port nobody reads before whole frames are discarded (frames are never cut).
constexpr std::size_t kMaxBacklogBytes = 16 * 1024;
/// How long an unplug waits for the host to read what was already sent.
constexpr auto kDrainTimeout = std::chrono::milliseconds(250);
constexpr auto kReplugRetry = std::chrono::seconds(1);
constexpr std::size_t kMaxGarbageBurst = 24;

void setNonBlocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL, 0);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
}

std::string joinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : ",") + name;
  return joined;
}

/// Index of the checksum byte a corruption flips.
std::size_t checksumIndex(OutputKind kind, std::size_t size) {
  if (kind == OutputKind::kTelemetry && size >= 3) return size - 3;  // SUM precedes the 1F 2F tail
  return size - 1;
}

}  // namespace

struct RobotSim::Port {
  struct PendingWrite {
    std::vector<uint8_t> bytes;
    std::size_t offset = 0;
    bool is_frame = true;  ///< false for garbage bursts
    OutputKind kind = OutputKind::kBaseReply;
    bool damaged = false;
  };

  std::string link;
  std::vector<std::string> device_names;
  std::unique_ptr<PseudoTerminal> pty;
  std::string slave_path;
  std::unique_ptr<protocol::StreamFramer> framer;
  std::deque<PendingWrite> backlog;
  std::size_t backlog_bytes = 0;
  bool plugged = true;
  bool draining = false;
  int drain_probe_fd = -1;  ///< our own handle on the slave, to see whether the host read it all
  TimePoint drain_deadline;
  TimePoint next_unplug = TimePoint::max();
  TimePoint replug_at = TimePoint::max();
  TimePoint next_garbage = TimePoint::max();
  std::mt19937 rng;
};

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
  if (!options_.enable_base && !options_.enable_body && !options_.enable_servo_bus) {
    throw std::invalid_argument("robot_sim: every device is disabled");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const TimePoint now = Clock::now();
  started_at_ = now;
  next_stats_write_ = now + fromSeconds(options_.stats_period_s);
  const FaultOptions& faults = options_.faults;
  if (options_.enable_base) base_ = std::make_unique<BaseSim>(options_.base, now);
  if (options_.enable_body) {
    options_.body.seed = faults.seed + 1;
    body_ = std::make_unique<BodySim>(options_.body, now);
  }
  if (options_.enable_servo_bus) {
    options_.servo_bus.seed = faults.seed + 2;
    servo_bus_ = std::make_unique<ServoBusSim>(options_.servo_bus, now);
  }

  // Devices whose effective links are equal share one pty.
  const auto portFor = [&](const std::optional<std::string>& own_link,
                           const std::string& name) -> Port* {
    const std::string link = own_link.value_or(options_.link);
    for (auto& port : ports_) {
      if (port->link == link) {
        port->device_names.push_back(name);
        return port.get();
      }
    }
    auto port = std::make_unique<Port>();
    Port* raw = port.get();
    // The framer calls back into the devices on this port; a frame for a device that lives on
    // another port (or is disabled) is only counted.
    port->framer = std::make_unique<protocol::StreamFramer>(
        protocol::FramerConfig::forSimulator(),
        [this, raw](FrameFamily family, const uint8_t* data, std::size_t size) {
          const TimePoint at = Clock::now();
          Outbox outbox;
          if (family == FrameFamily::kBase && base_port_ == raw) {
            base_->handleFrame(data, size, at, &outbox);
          } else if (family == FrameFamily::kSyncWrite && body_port_ == raw) {
            body_->handleSyncWrite(data, size);
          } else if (family == FrameFamily::kServoRequest && servo_port_ == raw) {
            servo_bus_->handleRequest(data, size, at);
          } else {
            ++counters_.frames_for_absent_device;
          }
          for (Outgoing& frame : outbox) route(std::move(frame));
        });
    port->link = link;
    port->device_names.push_back(name);
    port->rng.seed(faults.seed + 100 + static_cast<uint32_t>(ports_.size()));
    ports_.push_back(std::move(port));
    return raw;
  };
  if (base_) base_port_ = portFor(options_.base_link, "base");
  if (body_) body_port_ = portFor(options_.body_link, "body");
  if (servo_bus_) servo_port_ = portFor(options_.servo_link, "servo_bus");

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

void RobotSim::route(Outgoing frame) {
  switch (frame.kind) {
    case OutputKind::kBaseReply:
      return send(base_port_, std::move(frame));
    case OutputKind::kTelemetry:
      return send(body_port_, std::move(frame));
    case OutputKind::kServoResponse:
      return send(servo_port_, std::move(frame));
  }
}

void RobotSim::send(Port* port, Outgoing frame) {
  SendCounters& counters = counters_.sent[static_cast<std::size_t>(frame.kind)];
  if (port == nullptr || !port->plugged || port->draining || frame.bytes.empty()) {
    ++counters.discarded;
    return;
  }
  const FaultOptions& faults = options_.faults;
  std::uniform_real_distribution<double> chance(0.0, 1.0);
  bool damaged = false;
  std::vector<uint8_t>& bytes = frame.bytes;
  if (frame.kind == OutputKind::kServoResponse && faults.servo_fault_rate > 0 &&
      chance(port->rng) < faults.servo_fault_rate) {
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
    bytes[checksumIndex(frame.kind, bytes.size())] ^= 0xFF;
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
  port->backlog.push_back(Port::PendingWrite{std::move(bytes), 0, true, frame.kind, damaged});
  flush(port);
}

void RobotSim::flush(Port* port) {
  if (!port->pty || !port->pty->isOpen()) return;
  const int fd = port->pty->masterFd();
  while (!port->backlog.empty()) {
    Port::PendingWrite& pending = port->backlog.front();
    const std::size_t remaining = pending.bytes.size() - pending.offset;
    const ssize_t written = ::write(fd, pending.bytes.data() + pending.offset, remaining);
    if (written < 0) {
      if (errno == EINTR) continue;
      return;  // EAGAIN: the host is not reading right now; retry when poll says writable
    }
    counters_.bytes_sent += static_cast<uint64_t>(written);
    port->backlog_bytes -= static_cast<std::size_t>(written);
    pending.offset += static_cast<std::size_t>(written);
    if (pending.offset < pending.bytes.size()) return;
    if (pending.is_frame) {
      SendCounters& counters = counters_.sent[static_cast<std::size_t>(pending.kind)];
      ++(pending.damaged ? counters.damaged : counters.intact);
    }
    port->backlog.pop_front();
  }
}

void RobotSim::unplug(Port* port, TimePoint now) {
  for (const Port::PendingWrite& pending : port->backlog) {
    if (pending.is_frame) ++counters_.sent[static_cast<std::size_t>(pending.kind)].discarded;
  }
  port->backlog.clear();
  port->backlog_bytes = 0;
  if (port->drain_probe_fd >= 0) {
    ::close(port->drain_probe_fd);
    port->drain_probe_fd = -1;
  }
  port->pty->close();  // closes both sides and removes the symlink
  port->pty.reset();
  port->draining = false;
  port->plugged = false;
  port->replug_at = now + fromSeconds(options_.faults.unplug_duration_s);
  ++counters_.unplugs;
  event("robot_sim: " + joinNames(port->device_names) + " unplugged" +
        (port->link.empty() ? "" : " (link " + port->link + ")"));
}

void RobotSim::replug(Port* port, TimePoint now) {
  try {
    port->pty = std::make_unique<PseudoTerminal>(port->link);
  } catch (const transport::TransportError& error) {
    port->replug_at = now + kReplugRetry;
    event(std::string("robot_sim: replug failed, retrying: ") + error.what());
    return;
  }
  port->slave_path = port->pty->slavePath();
  setNonBlocking(port->pty->masterFd());
  port->framer->reset();  // a partial frame from before the unplug is meaningless now
  port->plugged = true;
  port->replug_at = TimePoint::max();
  port->next_unplug = now + fromSeconds(options_.faults.unplug_every_s);
  ++counters_.replugs;
  event("robot_sim: " + joinNames(port->device_names) + " on " + port->slave_path +
        (port->link.empty() ? "" : " (link " + port->link + ")"));
}

void RobotSim::step(TimePoint now) {
  Outbox outbox;
  if (base_) base_->tick(now, &outbox);
  if (body_) body_->tick(now, base_ ? base_->yawRate() : 0.0, &outbox);
  if (servo_bus_) servo_bus_->tick(now, &outbox);
  for (Outgoing& frame : outbox) route(std::move(frame));

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
  std::vector<pollfd> fds;
  std::vector<Port*> fd_ports;
  std::array<uint8_t, 4096> buffer{};
  int timeout_ms = 0;
  while (!stop_requested_) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      fds.clear();
      fd_ports.clear();
      fds.push_back(pollfd{wake_pipe_[0], POLLIN, 0});
      fd_ports.push_back(nullptr);
      for (auto& port : ports_) {
        if (!port->plugged || !port->pty) continue;
        const short events = port->backlog.empty() ? POLLIN : (POLLIN | POLLOUT);
        fds.push_back(pollfd{port->pty->masterFd(), events, 0});
        fd_ports.push_back(port.get());
      }
    }
    ::poll(fds.data(), fds.size(), timeout_ms);
    if (stop_requested_) break;

    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 1; i < fds.size(); ++i) {
      Port* port = fd_ports[i];
      if ((fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0 || !port->pty) continue;
      const int fd = port->pty->masterFd();
      for (int reads = 0; reads < 16; ++reads) {
        const ssize_t n = ::read(fd, buffer.data(), buffer.size());
        if (n <= 0) break;
        counters_.bytes_received += static_cast<uint64_t>(n);
        port->framer->feed(buffer.data(), static_cast<std::size_t>(n));
      }
    }
    const TimePoint now = Clock::now();
    step(now);

    TimePoint next = now + std::chrono::milliseconds(100);
    if (base_) next = std::min(next, base_->nextEvent());
    if (body_) next = std::min(next, body_->nextEvent());
    if (servo_bus_) next = std::min(next, servo_bus_->nextEvent());
    next = std::min(next, next_stats_write_);
    for (auto& port : ports_) {
      next = std::min({next, port->next_unplug, port->replug_at, port->next_garbage});
      if (port->draining) next = std::min(next, now + std::chrono::milliseconds(5));
    }
    const double wait_ms = std::chrono::duration<double, std::milli>(next - now).count();
    timeout_ms = wait_ms <= 0 ? 0 : static_cast<int>(std::ceil(wait_ms));
  }
}

SimStats RobotSim::snapshotLocked() const {
  SimStats stats = counters_;
  if (base_) stats.base = base_->stats();
  if (body_) stats.body = body_->stats();
  if (servo_bus_) stats.servo_bus = servo_bus_->stats();
  for (const auto& port : ports_) {
    const protocol::FramerStats& framer = port->framer->stats();
    stats.framer.bytes_in += framer.bytes_in;
    stats.framer.bytes_skipped += framer.bytes_skipped;
    stats.framer.checksum_errors += framer.checksum_errors;
    stats.framer.bad_tails += framer.bad_tails;
    stats.framer.bad_lengths += framer.bad_lengths;
    for (std::size_t f = 0; f < protocol::kFrameFamilyCount; ++f) {
      stats.framer.frames[f] += framer.frames[f];
    }
    // Bad sync-writes: the CRC failures the body's framer saw (on a shared port this also counts
    // bad frames of the other devices: the framer cannot tell whose a broken frame was).
    if (port.get() == body_port_) stats.body_port_checksum_errors = framer.checksum_errors;
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

namespace {

bool parseDouble(const std::string& text, double* value) {
  char* end = nullptr;
  errno = 0;
  const double parsed = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(parsed)) return false;
  *value = parsed;
  return true;
}

bool parseUnsigned(const std::string& text, uint64_t max, uint64_t* value) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
  errno = 0;
  const unsigned long long parsed = std::strtoull(text.c_str(), nullptr, 10);
  if (errno != 0 || parsed > max) return false;
  *value = parsed;
  return true;
}

bool parseIdList(const std::string& text, std::vector<uint8_t>* ids) {
  ids->clear();
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    uint64_t id = 0;
    if (!parseUnsigned(item, 254, &id)) return false;
    ids->push_back(static_cast<uint8_t>(id));
  }
  return true;
}

}  // namespace

std::string usage() {
  return R"USAGE(usage: robot_sim [options]
A simulated robot (AP1 base, servo controller board, UART bus servos) on pseudo-terminal(s).
Prints one line per pty: "robot_sim: <devices> on <slave path> (link <link>)".

Ports:
  --link PATH             symlink to the shared pty (default: none, just print the path)
  --base-link PATH        own pty for the base (devices naming the same link share a pty)
  --body-link PATH        own pty for the servo controller board
  --servo-link PATH       own pty for the servo bus
  --no-base | --no-body | --no-servo-bus   leave a device out
Devices:
  --battery PCT           battery percent the base reports (default 87)
  --servo-ids 1,2         body servo ids in telemetry order (default 1,2)
  --telemetry-rate HZ     telemetry frames per second (default 50, 0 = off)
  --foot                  every telemetry frame carries the foot block
  --foot-alternate        every other telemetry frame carries it
  --servo-speed TICKS_S   body servo speed bound in ticks/s (default 2048)
  --imu-noise             +-2 LSB noise on the IMU values
  --bus-servo-ids 0,1,2   ids on the servo bus (default 0,1,2)
  --offline-ids 7         ids that never answer
  --servo-latency-ms MS   servo bus answer latency (default 1.5)
Faults (seeded):
  --seed N                random seed (default 1)
  --garbage-rate HZ       random junk bursts per second and port
  --corrupt-rate P        probability a sent frame has its checksum byte flipped
  --drop-rate P           probability a sent frame loses one byte
  --unplug-every S        close the pty (and its link) every S seconds...
  --unplug-duration S     ...for S seconds, then recreate it at the same link (default 1)
  --servo-fault-rate P    probability a servo answer is garbled or missing
Output:
  --stats-file PATH       "key value" counters, rewritten every second and at exit
  --help                  this text
Arguments containing ":=" (roslaunch's __name:=..., __log:=...) are ignored.
)USAGE";
}

CommandLine parseCommandLine(int argc, const char* const* argv) {
  CommandLine result;
  SimOptions& options = result.options;
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.find(":=") != std::string::npos) continue;  // roslaunch remapping / special args
    args.push_back(arg);
  }

  const auto fail = [&result](const std::string& message) {
    result.error = message;
    return result;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string flag = args[i];
    std::optional<std::string> inline_value;
    const std::size_t equals = flag.find('=');
    if (flag.rfind("--", 0) == 0 && equals != std::string::npos) {
      inline_value = flag.substr(equals + 1);
      flag = flag.substr(0, equals);
    }
    // Fetches the flag's value, from "--flag=value" or from the next argument.
    std::string value;
    const auto takeValue = [&]() {
      if (inline_value) {
        value = *inline_value;
        return true;
      }
      if (i + 1 >= args.size()) return false;
      value = args[++i];
      return true;
    };
    const auto needValue = [&]() { return "missing value for " + flag; };
    const auto badValue = [&]() { return "bad value for " + flag + ": '" + value + "'"; };
    const auto probability = [&](double* target) {
      return takeValue() && parseDouble(value, target) && *target >= 0.0 && *target <= 1.0;
    };
    const auto nonNegative = [&](double* target) {
      return takeValue() && parseDouble(value, target) && *target >= 0.0;
    };
    const auto text = [&](auto* target) {  // std::string or std::optional<std::string>
      if (!takeValue()) return false;
      *target = value;
      return true;
    };

    const bool takes_value = flag != "--help" && flag != "-h" && flag != "--foot" &&
                             flag != "--foot-alternate" && flag != "--imu-noise" &&
                             flag != "--no-base" && flag != "--no-body" && flag != "--no-servo-bus";
    if (!takes_value && inline_value) return fail(flag + " takes no value");

    if (flag == "--help" || flag == "-h") {
      result.help = true;
    } else if (flag == "--foot") {
      options.body.foot_mode = FootMode::kAlways;
    } else if (flag == "--foot-alternate") {
      options.body.foot_mode = FootMode::kAlternate;
    } else if (flag == "--imu-noise") {
      options.body.imu_noise = true;
    } else if (flag == "--no-base") {
      options.enable_base = false;
    } else if (flag == "--no-body") {
      options.enable_body = false;
    } else if (flag == "--no-servo-bus") {
      options.enable_servo_bus = false;
    } else if (flag == "--link") {
      if (!text(&options.link)) return fail(needValue());
    } else if (flag == "--base-link") {
      if (!text(&options.base_link)) return fail(needValue());
    } else if (flag == "--body-link") {
      if (!text(&options.body_link)) return fail(needValue());
    } else if (flag == "--servo-link") {
      if (!text(&options.servo_link)) return fail(needValue());
    } else if (flag == "--stats-file") {
      if (!text(&options.stats_file)) return fail(needValue());
    } else if (flag == "--battery") {
      uint64_t percent = 0;
      if (!takeValue()) return fail(needValue());
      if (!parseUnsigned(value, 100, &percent)) return fail(badValue());
      options.base.battery_percent = static_cast<uint8_t>(percent);
    } else if (flag == "--seed") {
      uint64_t seed = 0;
      if (!takeValue()) return fail(needValue());
      if (!parseUnsigned(value, 0xFFFFFFFFu, &seed)) return fail(badValue());
      options.faults.seed = static_cast<uint32_t>(seed);
    } else if (flag == "--servo-ids" || flag == "--bus-servo-ids" || flag == "--offline-ids") {
      if (!takeValue()) return fail(needValue());
      std::vector<uint8_t>* ids = flag == "--servo-ids"       ? &options.body.servo_ids
                                  : flag == "--bus-servo-ids" ? &options.servo_bus.servo_ids
                                                              : &options.servo_bus.offline_ids;
      if (!parseIdList(value, ids)) return fail(badValue() + " (comma-separated ids 0..254)");
      if (flag == "--servo-ids" && ids->size() > protocol::body::kMaxTelemetryServos) {
        return fail("too many --servo-ids (at most 57 fit in a telemetry frame)");
      }
    } else if (flag == "--telemetry-rate") {
      if (!nonNegative(&options.body.telemetry_rate_hz)) return fail(badValue());
    } else if (flag == "--servo-speed") {
      if (!nonNegative(&options.body.servo_speed)) return fail(badValue());
    } else if (flag == "--servo-latency-ms") {
      double ms = 0;
      if (!nonNegative(&ms)) return fail(badValue());
      options.servo_bus.answer_latency_s = ms / 1000.0;
    } else if (flag == "--garbage-rate") {
      if (!nonNegative(&options.faults.garbage_rate_hz)) return fail(badValue());
    } else if (flag == "--corrupt-rate") {
      if (!probability(&options.faults.corrupt_rate)) return fail(badValue());
    } else if (flag == "--drop-rate") {
      if (!probability(&options.faults.drop_rate)) return fail(badValue());
    } else if (flag == "--servo-fault-rate") {
      if (!probability(&options.faults.servo_fault_rate)) return fail(badValue());
    } else if (flag == "--unplug-every") {
      if (!nonNegative(&options.faults.unplug_every_s)) return fail(badValue());
    } else if (flag == "--unplug-duration") {
      if (!nonNegative(&options.faults.unplug_duration_s)) return fail(badValue());
    } else {
      return fail("unknown argument: " + args[i]);
    }
  }
  if (!result.help && !options.enable_base && !options.enable_body && !options.enable_servo_bus) {
    return fail("--no-base, --no-body and --no-servo-bus together leave nothing to simulate");
  }
  return result;
}

std::string formatStats(const SimStats& stats) {
  std::ostringstream out;
  const auto line = [&out](const std::string& key, auto value) {
    out << key << ' ' << value << '\n';
  };
  out << std::fixed << std::setprecision(3);
  line("uptime_s", stats.uptime_s);

  const BaseSimStats& base = stats.base;
  line("base_frames_received", base.frames_received);
  line("base_seq_gaps", base.seq_gaps);
  line("base_resets", base.resets);
  line("base_speed_frames_applied", base.speed_frames_applied);
  line("base_speed_frames_ignored", base.speed_frames_ignored);
  line("base_errors_sent", base.errors_sent);
  line("base_timeouts", base.timeouts);
  line("base_battery_requests", base.battery_requests);
  line("base_encoder_clears", base.encoder_clears);
  line("base_unknown_frames", base.unknown_frames);
  line("base_in_error", base.in_error ? 1 : 0);
  line("left_ticks", base.left_ticks);
  line("right_ticks", base.right_ticks);
  line("last_left_speed", base.last_left_speed);
  line("last_right_speed", base.last_right_speed);

  const BodySimStats& body = stats.body;
  line("telemetry_generated", body.telemetry_generated);
  line("telemetry_with_foot", body.telemetry_with_foot);
  line("sync_writes_ok", body.sync_writes_ok);
  line("sync_writes_bad", body.sync_writes_malformed + stats.body_port_checksum_errors);
  line("sync_write_unknown_ids", body.sync_write_unknown_ids);
  line("yaw_rad", body.yaw_rad);
  for (const BodySimServoState& servo : body.servos) {
    const std::string prefix = "servo_" + std::to_string(servo.id);
    line(prefix + "_position", std::lround(servo.position));
    line(prefix + "_target", servo.target);
    line(prefix + "_speed", servo.speed);
  }

  const ServoBusSimStats& bus = stats.servo_bus;
  line("servo_requests", bus.requests);
  line("servo_answers", bus.answers);
  line("servo_broadcasts", bus.broadcasts);
  line("servo_unaddressed", bus.unaddressed);
  line("servo_unknown_data_ids", bus.unknown_data_ids);
  line("servo_malformed", bus.malformed);
  line("servo_writes_rejected", bus.writes_rejected);
  for (const BusServoSnapshot& servo : bus.servos) {
    line("bus_servo_" + std::to_string(servo.id) + "_angle_deg", servo.angle_deg);
  }

  static const char* const kKindNames[kOutputKindCount] = {"base_replies", "telemetry",
                                                           "servo_answers"};
  for (std::size_t k = 0; k < kOutputKindCount; ++k) {
    const std::string name = kKindNames[k];
    line(name + "_sent_intact", stats.sent[k].intact);
    line(name + "_sent_damaged", stats.sent[k].damaged);
    line(name + "_suppressed", stats.sent[k].suppressed);
    line(name + "_discarded", stats.sent[k].discarded);
  }

  line("rx_bytes", stats.bytes_received);
  line("rx_bytes_skipped", stats.framer.bytes_skipped);
  line("rx_checksum_errors", stats.framer.checksum_errors);
  line("rx_bad_lengths", stats.framer.bad_lengths);
  line("rx_frames_base", stats.framer.frames[static_cast<std::size_t>(FrameFamily::kBase)]);
  line("rx_frames_servo_request",
       stats.framer.frames[static_cast<std::size_t>(FrameFamily::kServoRequest)]);
  line("rx_frames_sync_write",
       stats.framer.frames[static_cast<std::size_t>(FrameFamily::kSyncWrite)]);
  line("frames_for_absent_device", stats.frames_for_absent_device);
  line("tx_bytes", stats.bytes_sent);
  line("garbage_bursts", stats.garbage_bursts);
  line("garbage_bytes", stats.garbage_bytes);
  line("unplugs", stats.unplugs);
  line("replugs", stats.replugs);
  return out.str();
}

}  // namespace serial_robot_driver::sim
