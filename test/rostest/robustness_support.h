// Helpers shared by the robustness rostests (multi_port, faults, soak): waiting by counting,
// topic counters, the driver's process (pid, open fds, threads, RSS) and its /diagnostics values.
//
// Header-only on purpose: each rostest is its own executable, and none of this belongs in a
// library the driver links.
#pragma once

#include <dirent.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace robustness {

using Clock = std::chrono::steady_clock;

inline double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Polls `done` every 10 ms until it holds or `timeout_s` has passed. The timeouts in these tests
/// are generous upper bounds for a busy machine, never the quantity under test.
inline bool waitFor(const std::function<bool()>& done, double timeout_s) {
  const Clock::time_point start = Clock::now();
  while (!done()) {
    if (secondsSince(start) > timeout_s) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

inline void sleepSeconds(double seconds) {
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

/// Counts the messages of one topic and keeps the most recent ones (all of them when keep == 0).
template <typename Msg>
class TopicCounter {
 public:
  TopicCounter(ros::NodeHandle& nh, const std::string& topic, std::size_t keep = 0)
      : keep_(keep) {
    // A deep queue: the counters are compared with the simulator's, so the test must drop nothing.
    sub_ = nh.subscribe<Msg>(topic, 2000, [this](const typename Msg::ConstPtr& msg) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++count_;
      messages_.push_back(*msg);
      if (keep_ > 0 && messages_.size() > keep_) messages_.erase(messages_.begin());
    });
  }
  uint64_t count() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return count_;
  }
  /// Messages received after the first `from` (only those still kept).
  std::vector<Msg> since(uint64_t from) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const uint64_t first_kept = count_ - messages_.size();
    const uint64_t skip = from > first_kept ? from - first_kept : 0;
    if (skip >= messages_.size()) return {};
    return std::vector<Msg>(messages_.begin() + static_cast<std::ptrdiff_t>(skip), messages_.end());
  }
  std::optional<Msg> last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (messages_.empty()) return std::nullopt;
    return messages_.back();
  }
  bool waitForCount(uint64_t n, double timeout_s) const {
    return waitFor([&] { return count() >= n; }, timeout_s);
  }
  bool waitConnected(double timeout_s) const {
    return waitFor([&] { return sub_.getNumPublishers() > 0; }, timeout_s);
  }

 private:
  ros::Subscriber sub_;
  const std::size_t keep_;
  mutable std::mutex mutex_;
  uint64_t count_ = 0;
  std::vector<Msg> messages_;
};

/// Reads the private parameter `key` of node `node` (e.g. "/soak/driver_node", "port").
inline std::string nodeParam(const std::string& node, const std::string& key) {
  std::string value;
  ros::param::get(node + "/" + key, value);
  return value;
}

/// The pid of a running ROS node, asked through its own XML-RPC API (getPid), so the test needs
/// neither a ~pid parameter nor a guess from /proc command lines. -1 when it cannot be found.
inline int nodePid(const std::string& node) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, payload, false)) return -1;
  const std::string uri = static_cast<std::string>(payload);
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(uri, host, port)) return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue pid_request, pid_response;
  pid_request[0] = ros::this_node::getName();
  if (!client.execute("getPid", pid_request, pid_response)) return -1;
  if (pid_response.getType() != XmlRpc::XmlRpcValue::TypeArray || pid_response.size() < 3 ||
      static_cast<int>(pid_response[0]) != 1) {
    return -1;
  }
  return static_cast<int>(pid_response[2]);
}

inline bool processAlive(int pid) { return pid > 0 && ::kill(pid, 0) == 0; }

/// Names in a /proc directory (fd, task), without "." and "..".
inline std::vector<std::string> listDirectory(const std::string& path) {
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

inline std::size_t openFdCount(int pid) {
  return listDirectory("/proc/" + std::to_string(pid) + "/fd").size();
}
inline std::size_t threadCount(int pid) {
  return listDirectory("/proc/" + std::to_string(pid) + "/task").size();
}
/// Where each open fd points ("/dev/pts/5", "socket:[123]", ...).
inline std::vector<std::string> openFdTargets(int pid) {
  std::vector<std::string> targets;
  const std::string dir = "/proc/" + std::to_string(pid) + "/fd/";
  for (const std::string& fd : listDirectory(dir)) {
    char buffer[512];
    const ssize_t n = ::readlink((dir + fd).c_str(), buffer, sizeof(buffer) - 1);
    if (n > 0) targets.emplace_back(buffer, static_cast<std::size_t>(n));
  }
  return targets;
}
/// Open fds on a pseudo-terminal slave or the pty multiplexer (a leaked port shows up here).
inline std::size_t ptyFdCount(int pid) {
  std::size_t count = 0;
  for (const std::string& target : openFdTargets(pid)) {
    if (target.rfind("/dev/pts/", 0) == 0 || target == "/dev/ptmx") ++count;
  }
  return count;
}
/// VmRSS in kB from /proc/<pid>/status (0 when unreadable).
inline long vmRssKb(int pid) {
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

/// What a process's resources look like at one moment.
struct ProcessSample {
  std::size_t fds = 0;
  std::size_t threads = 0;
  std::size_t pty_fds = 0;
  long rss_kb = 0;
};
inline ProcessSample sampleProcess(int pid) {
  return ProcessSample{openFdCount(pid), threadCount(pid), ptyFdCount(pid), vmRssKb(pid)};
}

/// The latest /diagnostics status of each name ending in one of the watched suffixes, as key/value
/// strings, with how many times it was received.
class DiagnosticsWatch {
 public:
  struct Status {
    uint64_t received = 0;  ///< how many statuses of this name arrived so far
    std::string message;
    std::map<std::string, std::string> values;

    std::string value(const std::string& key) const {
      const auto it = values.find(key);
      return it == values.end() ? std::string() : it->second;
    }
    uint64_t number(const std::string& key) const {
      const std::string text = value(key);
      return text.empty() ? 0 : std::stoull(text);
    }
    bool flag(const std::string& key) const { return value(key) == "True"; }
  };

  /// `node` is the driver's name without the leading slash ("soak/driver_node"); the updater
  /// prefixes every status with it, so nodes sharing /diagnostics are told apart.
  DiagnosticsWatch(ros::NodeHandle& nh, const std::string& node) : prefix_(node + ": ") {
    sub_ = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
          std::lock_guard<std::mutex> lock(mutex_);
          for (const auto& status : msg->status) {
            if (status.name.rfind(prefix_, 0) != 0) continue;
            Status& stored = statuses_[status.name.substr(prefix_.size())];
            ++stored.received;
            stored.message = status.message;
            stored.values.clear();
            for (const auto& kv : status.values) stored.values[kv.key] = kv.value;
          }
        });
  }

  /// The latest status named `name` (after the node prefix), e.g. "port /tmp/x", "body".
  Status latest(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = statuses_.find(name);
    return it == statuses_.end() ? Status{} : it->second;
  }
  /// Waits for a status of `name` received after `after_count` that satisfies `pred`.
  std::optional<Status> waitFor(const std::string& name, uint64_t after_count,
                                const std::function<bool(const Status&)>& pred,
                                const std::function<bool()>& keep_waiting, double timeout_s) const {
    std::optional<Status> found;
    robustness::waitFor(
        [&] {
          const Status status = latest(name);
          if (status.received > after_count && pred(status)) {
            found = status;
            return true;
          }
          return !keep_waiting();
        },
        timeout_s);
    return found;
  }
  std::vector<std::string> names() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> result;
    for (const auto& [name, status] : statuses_) result.push_back(name);
    return result;
  }

 private:
  const std::string prefix_;
  ros::Subscriber sub_;
  mutable std::mutex mutex_;
  std::map<std::string, Status> statuses_;
};

}  // namespace robustness
