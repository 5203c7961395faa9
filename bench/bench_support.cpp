#include "bench_support.h"

#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace serial_robot_driver::bench {

double toMs(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }
double toSeconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }
Clock::duration fromSeconds(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

std::string format(const char* fmt, ...) {
  char buffer[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buffer, sizeof(buffer), fmt, args);
  va_end(args);
  return buffer;
}

// --- statistics -------------------------------------------------------------------------------

double percentile(std::vector<double> samples, double q) {
  if (samples.empty()) return 0.0;
  // Nearest rank: the smallest sample with at least q % of the samples at or below it.
  const auto rank = static_cast<std::size_t>(std::ceil(q / 100.0 * samples.size()));
  const std::size_t index = std::min(samples.size() - 1, rank == 0 ? 0 : rank - 1);
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(index),
                   samples.end());
  return samples[index];
}

Summary summarize(const std::vector<double>& samples) {
  Summary summary;
  summary.count = samples.size();
  if (samples.empty()) return summary;
  const auto [min, max] = std::minmax_element(samples.begin(), samples.end());
  summary.min = *min;
  summary.max = *max;
  summary.mean = std::accumulate(samples.begin(), samples.end(), 0.0) / samples.size();
  double squares = 0.0;
  for (double sample : samples) squares += (sample - summary.mean) * (sample - summary.mean);
  summary.stddev = std::sqrt(squares / samples.size());
  summary.p50 = percentile(samples, 50);
  summary.p99 = percentile(samples, 99);
  return summary;
}

// --- stop requests and child processes ------------------------------------------------------

namespace {

std::atomic<bool> g_stop_requested{false};

// Process groups of the running children, readable from the signal handler (lock-free atomics).
constexpr std::size_t kMaxChildren = 32;
std::atomic<pid_t> g_child_groups[kMaxChildren];

void registerChild(pid_t pid) {
  for (auto& slot : g_child_groups) {
    pid_t expected = 0;
    if (slot.compare_exchange_strong(expected, pid)) return;
  }
}

void unregisterChild(pid_t pid) {
  for (auto& slot : g_child_groups) {
    pid_t expected = pid;
    if (slot.compare_exchange_strong(expected, 0)) return;
  }
}

void onStopSignal(int) {
  if (g_stop_requested.exchange(true)) {
    // Second signal: the user means it. Only async-signal-safe calls from here on.
    for (auto& slot : g_child_groups) {
      const pid_t group = slot.load();
      if (group > 0) ::kill(-group, SIGKILL);
    }
    ::_exit(130);
  }
}

}  // namespace

void installStopHandler() {
  struct sigaction action {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

bool stopRequested() { return g_stop_requested.load(); }

bool sleepUntil(Clock::time_point deadline) {
  // Short slices so a stop request is seen quickly; the last slice ends exactly at the deadline.
  constexpr auto kSlice = std::chrono::milliseconds(100);
  while (!stopRequested()) {
    const auto now = Clock::now();
    if (now >= deadline) return true;
    std::this_thread::sleep_until(std::min(deadline, now + kSlice));
  }
  return false;
}

bool waitUntil(const std::function<bool()>& condition, Clock::duration timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!stopRequested()) {
    if (condition()) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

ChildProcess::ChildProcess(std::string label, std::vector<std::string> argv,
                           const std::string& log_path)
    : label_(std::move(label)) {
  std::vector<char*> args;
  for (auto& arg : argv) args.push_back(arg.data());
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed: " + std::string(std::strerror(errno)));
  if (pid == 0) {
    // Child: the normal policy even when the benchmark's threads run SCHED_FIFO; its own
    // process group (so the whole tree can be signalled); dies with the benchmark.
    const sched_param normal{};
    ::sched_setscheduler(0, SCHED_OTHER, &normal);
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(127);
    const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    const int null = ::open("/dev/null", O_RDONLY);
    if (null >= 0) ::dup2(null, STDIN_FILENO);
    if (log >= 0) {
      ::dup2(log, STDOUT_FILENO);
      ::dup2(log, STDERR_FILENO);
    }
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    ::execvp(args[0], args.data());
    std::fprintf(stderr, "exec %s failed: %s\n", args[0], std::strerror(errno));
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here: the child may not have run yet when we signal it
  pid_ = pid;
  registerChild(pid);
}

ChildProcess::~ChildProcess() { stop(); }

bool ChildProcess::running() {
  if (exited_ || pid_ <= 0) return false;
  if (::waitpid(pid_, &status_, WNOHANG) == pid_) {
    exited_ = true;
    ::kill(-pid_, SIGKILL);  // whatever the leader left behind in its group
    unregisterChild(pid_);
    return false;
  }
  return true;
}

int ChildProcess::stop(std::chrono::milliseconds grace) {
  if (running()) {
    ::kill(-pid_, SIGINT);
    const auto deadline = Clock::now() + grace;
    while (running() && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (running()) {
      ::kill(-pid_, SIGKILL);
      ::waitpid(pid_, &status_, 0);
      exited_ = true;
      unregisterChild(pid_);
    }
  }
  if (WIFEXITED(status_)) return WEXITSTATUS(status_);
  if (WIFSIGNALED(status_)) return -WTERMSIG(status_);
  return 0;
}

double processCpuSeconds(pid_t pid) {
  // The kernel's per-process CPU clock counts nanoseconds (threads that have exited included);
  // /proc/<pid>/stat counts 10 ms ticks, too coarse for a node using ~2 % of a core.
  clockid_t clock{};
  timespec now{};
  if (::clock_getcpuclockid(pid, &clock) == 0 && ::clock_gettime(clock, &now) == 0) {
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
  }
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  // The command name (field 2) may contain spaces; the fields after its ')' start at field 3.
  const std::size_t name_end = text.rfind(')');
  if (name_end == std::string::npos) return 0.0;
  std::istringstream fields(text.substr(name_end + 1));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int number = 3; fields >> field && number <= 15; ++number) {
    if (number == 14) utime = std::stoull(field);
    if (number == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

std::map<pid_t, ThreadCpu> threadCpuSeconds(pid_t pid) {
  std::map<pid_t, ThreadCpu> threads;
  const std::string tasks = "/proc/" + std::to_string(pid) + "/task/";
  DIR* dir = ::opendir(tasks.c_str());
  if (dir == nullptr) return threads;
  while (const dirent* entry = ::readdir(dir)) {
    char* end = nullptr;
    const long tid = std::strtol(entry->d_name, &end, 10);
    if (end == entry->d_name || *end != '\0') continue;  // "." and ".."
    std::ifstream comm(tasks + entry->d_name + "/comm");
    std::ifstream schedstat(tasks + entry->d_name + "/schedstat");
    ThreadCpu thread;
    unsigned long long on_cpu_ns = 0;
    if (!std::getline(comm, thread.name) || !(schedstat >> on_cpu_ns)) continue;  // just exited
    thread.seconds = 1e-9 * static_cast<double>(on_cpu_ns);
    threads[static_cast<pid_t>(tid)] = thread;
  }
  ::closedir(dir);
  return threads;
}

CpuWindow::CpuWindow(pid_t pid)
    : pid_(pid), cpu_start_(processCpuSeconds(pid)), wall_start_(Clock::now()) {}

double CpuWindow::percent() const {
  const double wall = toSeconds(Clock::now() - wall_start_);
  return wall > 0 ? 100.0 * (processCpuSeconds(pid_) - cpu_start_) / wall : 0.0;
}

int findFreeTcpPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket failed");
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0;
  ::close(fd);
  if (!ok) throw std::runtime_error("cannot find a free TCP port");
  return ntohs(address.sin_port);
}

// --- pty ----------------------------------------------------------------------------------------

bool writeFrameOrDrop(sim::PseudoTerminal& pty, const std::vector<uint8_t>& frame) {
  ssize_t written;
  do {
    written = ::write(pty.masterFd(), frame.data(), frame.size());
  } while (written < 0 && errno == EINTR);
  return written == static_cast<ssize_t>(frame.size());
}

// --- results ------------------------------------------------------------------------------------

const std::vector<std::string>& ResultTable::defaultColumns() {
  static const std::vector<std::string> columns{"measurement", "value", "goal", "verdict"};
  return columns;
}

std::string verdict(bool met) { return met ? "ok" : "MISSED"; }

namespace {
/// Columns a UTF-8 string takes on a terminal (continuation bytes take none; no wide characters).
std::size_t displayWidth(const std::string& text) {
  std::size_t width = 0;
  for (unsigned char c : text) width += (c & 0xC0) != 0x80;
  return width;
}
}  // namespace

ResultTable::Section& ResultTable::current() {
  if (sections_.empty()) section("");
  return sections_.back();
}

void ResultTable::section(const std::string& title, std::vector<std::string> columns) {
  sections_.push_back({title, std::move(columns), {}, {}});
}

void ResultTable::row(std::vector<std::string> cells) {
  cells.resize(current().columns.size());
  current().rows.push_back(std::move(cells));
}

void ResultTable::row(const std::string& measurement, const std::string& value,
                      const std::string& goal, std::optional<bool> met) {
  row({measurement, value, goal, met ? verdict(*met) : ""});
}

void ResultTable::note(const std::string& text) { current().notes.push_back(text); }

std::string ResultTable::markdown() const {
  std::ostringstream out;
  for (const Section& section : sections_) {
    if (!section.title.empty()) out << "\n### " << section.title << "\n\n";
    if (!section.rows.empty()) {
      std::vector<std::size_t> widths;
      for (const std::string& column : section.columns) {
        widths.push_back(std::max<std::size_t>(3, displayWidth(column)));
      }
      for (const auto& row : section.rows) {
        for (std::size_t i = 0; i < row.size(); ++i) {
          widths[i] = std::max(widths[i], displayWidth(row[i]));
        }
      }
      auto line = [&](const std::vector<std::string>& cells) {
        for (std::size_t i = 0; i < cells.size(); ++i) {
          out << "| " << cells[i] << std::string(widths[i] - displayWidth(cells[i]), ' ') << " ";
        }
        out << "|\n";
      };
      line(section.columns);
      std::vector<std::string> rule;
      for (std::size_t width : widths) rule.push_back(std::string(width, '-'));
      line(rule);
      for (const auto& row : section.rows) line(row);
    }
    for (const std::string& note : section.notes) out << "\n" << note << "\n";
  }
  return out.str();
}

}  // namespace serial_robot_driver::bench
