// ROS-free helpers for tests that start or watch other processes (see the header).
#include "support/process_support.h"

#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <sstream>

#include "support/test_helpers.h"

extern char** environ;

namespace test_support {

ChildProcess::ChildProcess(const std::string& program, const std::vector<std::string>& args,
                           const std::vector<std::string>& extra_env) {
  // argv and envp are built before fork: the child of a threaded process must not allocate.
  std::vector<std::string> arg_strings = {program};
  arg_strings.insert(arg_strings.end(), args.begin(), args.end());
  std::vector<std::string> env_strings = extra_env;
  for (char** entry = environ; *entry != nullptr; ++entry) {
    const std::string text = *entry;
    const std::string name = text.substr(0, text.find('=') + 1);
    bool replaced = false;
    for (const std::string& extra : extra_env) replaced |= extra.rfind(name, 0) == 0;
    if (!replaced) env_strings.push_back(text);
  }
  std::vector<char*> argv, envp;
  for (std::string& arg : arg_strings) argv.push_back(arg.data());
  argv.push_back(nullptr);
  for (std::string& entry : env_strings) envp.push_back(entry.data());
  envp.push_back(nullptr);

  int fds[2];
  if (::pipe(fds) != 0) return;
  pid_ = ::fork();
  if (pid_ == 0) {
    ::setpgid(0, 0);  // its own group: the destructor can stop whatever it starts in turn
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    // Leave the test's own sockets and ptys behind.
    for (int fd = 3; fd < 1024; ++fd) ::close(fd);
    ::execvpe(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  ::setpgid(pid_, pid_);  // also here: the child may not have run yet
  ::close(fds[1]);
  output_fd_ = fds[0];
  // Drained all the time, so a chatty child never blocks on a full pipe.
  drainer_ = std::thread([this] { drain(); });
}

ChildProcess::~ChildProcess() {
  if (running()) {
    ::kill(-pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  if (drainer_.joinable()) drainer_.join();  // EOF once the child is gone
  if (output_fd_ >= 0) ::close(output_fd_);
}

void ChildProcess::signal(int sig) {
  if (running()) ::kill(pid_, sig);
}

std::optional<int> ChildProcess::waitExit(double timeout_s) {
  waitFor(
      [&] {
        if (status_) return true;
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) status_ = status;
        return status_.has_value();
      },
      timeout_s);
  if (status_ && drainer_.joinable()) drainer_.join();  // all of its output
  return status_;
}

std::string ChildProcess::output() const {
  std::lock_guard<std::mutex> lock(output_mutex_);
  return output_;
}

void ChildProcess::drain() {
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(output_fd_, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    std::lock_guard<std::mutex> lock(output_mutex_);
    output_.append(buffer, static_cast<std::size_t>(n));
  }
}

void removeStaleLink(const std::string& path) {
  struct stat info {};
  if (::lstat(path.c_str(), &info) == 0 && S_ISLNK(info.st_mode)) ::unlink(path.c_str());
}

bool processAlive(int pid) { return pid > 0 && ::kill(pid, 0) == 0; }

std::vector<std::string> listDirectory(const std::string& path) {
  std::vector<std::string> names;
  DIR* dir = ::opendir(path.c_str());
  if (dir == nullptr) return names;
  while (dirent* entry = ::readdir(dir)) {
    const std::string name = entry->d_name;
    if (name != "." && name != "..") names.push_back(name);
  }
  ::closedir(dir);
  return names;
}

std::size_t openFdCount(int pid) {
  return listDirectory("/proc/" + std::to_string(pid) + "/fd").size();
}

std::size_t threadCount(int pid) {
  return listDirectory("/proc/" + std::to_string(pid) + "/task").size();
}

std::vector<std::string> openFdTargets(int pid) {
  std::vector<std::string> targets;
  const std::string dir = "/proc/" + std::to_string(pid) + "/fd/";
  for (const std::string& fd : listDirectory(dir)) {
    char buffer[512];
    const ssize_t n = ::readlink((dir + fd).c_str(), buffer, sizeof(buffer) - 1);
    if (n > 0) targets.emplace_back(buffer, static_cast<std::size_t>(n));
  }
  return targets;
}

std::size_t ptyFdCount(int pid) {
  std::size_t count = 0;
  for (const std::string& target : openFdTargets(pid)) {
    if (target.rfind("/dev/pts/", 0) == 0 || target == "/dev/ptmx") ++count;
  }
  return count;
}

long vmRssKb(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      std::istringstream fields(line.substr(6));
      long kb = 0;
      fields >> kb;
      return kb;
    }
  }
  return 0;
}

ProcessSample sampleProcess(int pid) {
  return ProcessSample{openFdCount(pid), threadCount(pid), ptyFdCount(pid), vmRssKb(pid)};
}

}  // namespace test_support
