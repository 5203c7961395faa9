// ROS-free helpers shared by the driver benchmarks: sample statistics, child processes that never
// outlive the benchmark, CPU accounting from /proc, non-blocking frame writes to a pty, and the
// result table. The pty reader that timestamps every verified frame is the tests' one
// (test/support/pty_frame_reader.h).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/sim/pseudo_terminal.h"

namespace serial_robot_driver::bench {

using Clock = std::chrono::steady_clock;

double toMs(Clock::duration d);
double toSeconds(Clock::duration d);
Clock::duration fromSeconds(double seconds);

// --- statistics -------------------------------------------------------------------------------

struct Summary {
  std::size_t count = 0;
  double min = 0, max = 0, mean = 0, stddev = 0;
  double p50 = 0, p99 = 0;
};

/// Nearest-rank percentile (0 < q <= 100) of `samples`; 0 for an empty set.
double percentile(std::vector<double> samples, double q);
Summary summarize(const std::vector<double>& samples);

// --- stop requests and child processes ------------------------------------------------------

/// SIGINT/SIGTERM set a flag that every section polls; a second signal kills the children and
/// exits at once.
void installStopHandler();
bool stopRequested();
/// Sleeps until `deadline` or a stop request; false when stopped.
bool sleepUntil(Clock::time_point deadline);
/// Polls `condition` every few ms until it holds (true), `timeout` passes or a stop is requested.
bool waitUntil(const std::function<bool()>& condition, Clock::duration timeout);

/// A program started with fork/exec in its own process group, its output appended to a log file.
/// The destructor stops it (SIGINT, then SIGKILL after `grace`); PR_SET_PDEATHSIG and the
/// signal handler cover a benchmark that dies without running destructors.
class ChildProcess {
 public:
  ChildProcess(std::string label, std::vector<std::string> argv, const std::string& log_path);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  const std::string& label() const { return label_; }
  /// True while the process has not exited (reaps it when it has).
  bool running();
  /// SIGINT to the group, waits up to `grace`, then SIGKILL. Returns the exit status (or -signal).
  int stop(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));

 private:
  std::string label_;
  pid_t pid_ = -1;
  int status_ = 0;
  bool exited_ = false;
};

/// User + system CPU time of a process in seconds (its kernel CPU clock, ns resolution; falls
/// back to /proc/<pid>/stat, clock-tick resolution).
double processCpuSeconds(pid_t pid);

/// One thread's on-CPU time so far (the scheduler's count, /proc/<pid>/task/<tid>/schedstat, ns).
struct ThreadCpu {
  std::string name;  ///< its comm: what pthread_setname_np set, else the process's name
  double seconds = 0;
};

/// Every thread of a process now, by tid; empty when the process is gone.
std::map<pid_t, ThreadCpu> threadCpuSeconds(pid_t pid);

/// Measures a process's CPU share over a window: construct at the start, call percent() at the end.
class CpuWindow {
 public:
  explicit CpuWindow(pid_t pid);
  /// CPU time over wall time since construction, in percent of one core.
  double percent() const;

 private:
  pid_t pid_;
  double cpu_start_;
  Clock::time_point wall_start_;
};

/// A TCP port nobody listens on right now (bind to port 0 and ask).
int findFreeTcpPort();

// --- pty ----------------------------------------------------------------------------------------

/// Writes one whole frame to the pty master without blocking, the way a UART overruns: when the
/// buffer cannot take the frame at once, the rest is dropped and false is returned.
bool writeFrameOrDrop(sim::PseudoTerminal& pty, const std::vector<uint8_t>& frame);

// --- results ------------------------------------------------------------------------------------

/// Result sections, each a title, a table and notes, rendered as Markdown so the same text reads
/// well on a terminal and in a file.
class ResultTable {
 public:
  static const std::vector<std::string>& defaultColumns();  ///< measurement, value, goal, verdict

  /// Starts a new section; the rows and notes that follow belong to it.
  void section(const std::string& title, std::vector<std::string> columns = defaultColumns());
  void row(std::vector<std::string> cells);
  /// A row of the default columns; `met`: nullopt for a measurement without a goal.
  void row(const std::string& measurement, const std::string& value, const std::string& goal = "",
           std::optional<bool> met = std::nullopt);
  void note(const std::string& text);
  std::string markdown() const;

 private:
  struct Section {
    std::string title;
    std::vector<std::string> columns;
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> notes;
  };
  Section& current();
  std::vector<Section> sections_;
};

/// "ok" / "MISSED" for a goal check.
std::string verdict(bool met);

/// printf-style formatting into a std::string.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

}  // namespace serial_robot_driver::bench
