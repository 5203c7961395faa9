// ROS-free helpers for tests that start or watch other processes: a child process with captured
// output, and /proc readers (open fds, threads, RSS) for leak checks.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace test_support {

/// A program started with fork/exec in its own process group; stdout and stderr go to a pipe read
/// by output(). The destructor kills the group (SIGKILL) if the program is still running.
class ChildProcess {
 public:
  /// Starts `program` (a path, or a name looked up in PATH) with `args`; `extra_env` entries
  /// ("NAME=value") replace or add to this process's environment for the child.
  ChildProcess(const std::string& program, const std::vector<std::string>& args,
               const std::vector<std::string>& extra_env = {});
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  bool running() const { return pid_ > 0 && !status_; }
  void signal(int sig);
  /// Waits for the process to exit; its wait status, or nullopt on timeout.
  std::optional<int> waitExit(double timeout_s);
  std::string output() const;

 private:
  void drain();

  pid_t pid_ = -1;
  int output_fd_ = -1;
  std::optional<int> status_;
  mutable std::mutex output_mutex_;
  std::string output_;
  std::thread drainer_;
};

/// Removes `path` if it is a symlink (left behind by a pty of an earlier run).
void removeStaleLink(const std::string& path);

bool processAlive(int pid);

/// Names in a /proc directory (fd, task), without "." and "..".
std::vector<std::string> listDirectory(const std::string& path);
std::size_t openFdCount(int pid);
std::size_t threadCount(int pid);
/// Where each open fd points ("/dev/pts/5", "socket:[123]", ...).
std::vector<std::string> openFdTargets(int pid);
/// Open fds on a pseudo-terminal slave or the pty multiplexer (a leaked port shows up here).
std::size_t ptyFdCount(int pid);
/// VmRSS in kB from /proc/<pid>/status (0 when unreadable).
long vmRssKb(int pid);

/// What a process's resources look like at one moment.
struct ProcessSample {
  std::size_t fds = 0;
  std::size_t threads = 0;
  std::size_t pty_fds = 0;
  long rss_kb = 0;
};
ProcessSample sampleProcess(int pid);

}  // namespace test_support
