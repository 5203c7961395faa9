// ROS helpers shared by the rostests: a main() scaffold, topic counters, the driver's process as
// the master knows it, and its /diagnostics values. The ROS-free helpers are in test_helpers.h,
// process_support.h and pty_frame_reader.h.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "serial_robot_driver/sim/robot_sim.h"
#include "support/process_support.h"
#include "support/test_helpers.h"

namespace test_support {

/// ros::init and a running AsyncSpinner for a rostest's main(), after testing::InitGoogleTest;
/// the destructor stops the spinner and shuts ROS down.
class RosTestNode {
 public:
  RosTestNode(int& argc, char** argv, const std::string& name, int spinner_threads = 2);
  ~RosTestNode();
  RosTestNode(const RosTestNode&) = delete;
  RosTestNode& operator=(const RosTestNode&) = delete;

 private:
  std::unique_ptr<ros::NodeHandle> nh_;  // keeps the node started while the tests run
  std::unique_ptr<ros::AsyncSpinner> spinner_;
};

/// The driver_node executable: the ~driver_path parameter, else the one next to this test binary
/// (devel/lib/serial_robot_driver/). Empty when not found.
std::string findDriverNode();

/// Whether `node` (e.g. "/ns/driver_node") has this process's subscriber of `topic` among its
/// publication's subscribers, asked through the node's own XML-RPC API (getBusInfo).
bool nodeCountsSubscriber(const std::string& node, const std::string& topic);

/// Counts the messages of one topic and keeps the most recent ones (all of them when keep == 0).
template <typename Msg>
class TopicCounter {
 public:
  TopicCounter(ros::NodeHandle& nh, const std::string& topic, std::size_t keep = 0) : keep_(keep) {
    // A deep queue: the counters are compared with the simulator's, so the test must drop nothing.
    sub_ = nh.subscribe<Msg>(topic, 2000, [this](const typename Msg::ConstPtr& msg) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++count_;
      messages_.push_back(*msg);
      if (keep_ > 0 && messages_.size() > keep_) messages_.erase(messages_.begin());
    });
  }
  // The callback runs on the spinner thread and the members below die before sub_ would:
  // shutdown() waits for a running callback (a test's counters going out of scope while a message
  // arrived crashed the test process).
  ~TopicCounter() { sub_.shutdown(); }
  TopicCounter(const TopicCounter&) = delete;
  TopicCounter& operator=(const TopicCounter&) = delete;
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
  /// Stronger than waitConnected(): until `node` (e.g. "/ns/driver_node") counts this subscriber
  /// on its side, which it does a little later. A node that publishes only to subscribers it
  /// counts (driver_node) publishes the message of one frame from then on.
  bool waitCountedBy(const std::string& node, double timeout_s) const {
    return waitFor([&] { return nodeCountsSubscriber(node, sub_.getTopic()); }, timeout_s);
  }

 private:
  ros::Subscriber sub_;
  const std::size_t keep_;
  mutable std::mutex mutex_;
  uint64_t count_ = 0;
  std::vector<Msg> messages_;
};

/// Whether a service call that roscpp reported failed is worth another try: `service` is still
/// advertised (a service not there yet, or gone with its node, answers nothing however often it is
/// called). Logs the lost try on stderr.
bool retryLostServiceCall(const std::string& service, int attempt, int tries);

/// ros::service::call, and again (up to three tries) when roscpp lost the call while the service
/// is advertised. Every roscpp server, driver_node's too, now and then closes a freshly accepted
/// connection on a busy machine: its poll loop hands a stale "peer closed" event (POLLRDHUP) of a
/// socket just closed to the new socket that reuses its descriptor (roscpp guards against that for
/// POLLERR, POLLHUP and POLLNVAL only), and the client gets no answer.
/// bench/service_call_loss.sh measures it: about 1 call in 1,600 to 12,000 under CPU hogs. A
/// persistent connection loses fewer, but one made per call has also hung a call for good in that
/// benchmark (no answer, no error), so the tests keep roscpp's default connection and call again.
/// The servo services always answer (a refusal is in the response), so a false here means the
/// call never reached them or its answer was lost on the way; a call the node had done before the
/// loss is done twice: tests that count frames then fail, never pass wrongly.
template <typename Service>
bool callService(const std::string& service, Service& srv) {
  constexpr int kTries = 3;
  for (int attempt = 1; attempt <= kTries; ++attempt) {
    if (ros::service::call(service, srv)) return true;
    if (!retryLostServiceCall(service, attempt, kTries)) return false;
  }
  return false;
}

/// Reads the private parameter `key` of node `node` (e.g. "/soak/driver_node", "port").
std::string nodeParam(const std::string& node, const std::string& key);

/// The pid of a running ROS node, asked through its own XML-RPC API (getPid), so the test needs
/// neither a ~pid parameter nor a guess from /proc command lines. -1 when it cannot be found.
int nodePid(const std::string& node);

/// The latest /diagnostics status of each name the node publishes, as key/value strings, with how
/// many times it was received.
class DiagnosticsWatch {
 public:
  struct Status {
    uint64_t received = 0;  ///< how many statuses of this name arrived so far
    int level = 0;          ///< diagnostic_msgs::DiagnosticStatus OK / WARN / ERROR / STALE
    std::string message;
    std::map<std::string, std::string> values;

    /// The value of `key`, "" when absent.
    std::string value(const std::string& key) const;
    /// The value of `key` as a counter, 0 when absent.
    uint64_t number(const std::string& key) const;
    bool flag(const std::string& key) const { return value(key) == "True"; }
  };

  /// `node` is the driver's name without the leading slash ("soak/driver_node"); the updater
  /// prefixes every status with it, so nodes sharing /diagnostics are told apart.
  DiagnosticsWatch(ros::NodeHandle& nh, const std::string& node);

  /// The latest status named `name` (after the node prefix), e.g. "port /tmp/x", "body".
  Status latest(const std::string& name) const;
  /// Waits for a status of `name` received after `after_count` that satisfies `pred`.
  std::optional<Status> waitFor(const std::string& name, uint64_t after_count,
                                const std::function<bool(const Status&)>& pred,
                                const std::function<bool()>& keep_waiting, double timeout_s) const;
  std::vector<std::string> names() const;

 private:
  /// Shared with the subscriber's callback, so a watch destroyed while a message is being
  /// handled on a spinner thread leaves that callback a live state to finish with.
  struct State {
    std::string prefix;
    std::mutex mutex;
    std::map<std::string, Status> statuses;
  };
  std::shared_ptr<State> state_;
  ros::Subscriber sub_;
};

/// Publishes `engaged` on `e_stop` and waits (up to `timeout_s`) until the node's "e_stop"
/// diagnostic status reports that state; false when it never did.
bool setEStopAndWait(ros::Publisher& e_stop, const DiagnosticsWatch& diagnostics, bool engaged,
                     double timeout_s);

/// RUN_ALL_TESTS() against an in-process simulated robot on `options.link`: started before the
/// tests, `*robot` pointing at it while they run, stopped after them. Returns RUN_ALL_TESTS()'s.
int runAllTestsWithSim(const serial_robot_driver::sim::SimOptions& options,
                       serial_robot_driver::sim::RobotSim** robot);

}  // namespace test_support
