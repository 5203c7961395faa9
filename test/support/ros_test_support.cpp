// ROS helpers shared by the rostests (see the header).
#include "support/ros_test_support.h"

#include <gtest/gtest.h>
#include <ros/network.h>
#include <ros/service.h>
#include <std_msgs/Bool.h>
#include <unistd.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdio>
#include <optional>

namespace test_support {

RosTestNode::RosTestNode(int& argc, char** argv, const std::string& name, int spinner_threads) {
  ros::init(argc, argv, name);
  nh_ = std::make_unique<ros::NodeHandle>();
  spinner_ = std::make_unique<ros::AsyncSpinner>(spinner_threads);
  spinner_->start();
}

RosTestNode::~RosTestNode() {
  spinner_->stop();
  ros::shutdown();
}

bool retryLostServiceCall(const std::string& service, int attempt, int tries) {
  if (attempt >= tries || !ros::service::exists(service, false)) return false;
  std::fprintf(stderr, "%s: roscpp lost the call (try %d of %d), calling again\n", service.c_str(),
               attempt, tries);
  return true;
}

std::string findDriverNode() {
  std::string from_param;
  if (ros::param::get("~driver_path", from_param) && !from_param.empty()) return from_param;
  char self[4096];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (n <= 0) return {};
  std::string dir(self, static_cast<std::size_t>(n));
  dir = dir.substr(0, dir.find_last_of('/'));
  const std::string path = dir + "/driver_node";
  return ::access(path.c_str(), X_OK) == 0 ? path : std::string();
}

std::string nodeParam(const std::string& node, const std::string& key) {
  std::string value;
  ros::param::get(node + "/" + key, value);
  return value;
}

namespace {

/// Calls `method` of `node`'s XML-RPC API with this node as the caller; the reply's value
/// (its third field) when the call succeeded.
std::optional<XmlRpc::XmlRpcValue> callNodeApi(const std::string& node, const std::string& method) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, payload, false)) return std::nullopt;
  const std::string uri = static_cast<std::string>(payload);
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(uri, host, port)) return std::nullopt;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue api_request, api_response;
  api_request[0] = ros::this_node::getName();
  if (!client.execute(method.c_str(), api_request, api_response)) return std::nullopt;
  if (api_response.getType() != XmlRpc::XmlRpcValue::TypeArray || api_response.size() < 3 ||
      static_cast<int>(api_response[0]) != 1) {
    return std::nullopt;
  }
  return api_response[2];
}

}  // namespace

int nodePid(const std::string& node) {
  const std::optional<XmlRpc::XmlRpcValue> pid = callNodeApi(node, "getPid");
  return pid ? static_cast<int>(*pid) : -1;
}

bool nodeCountsSubscriber(const std::string& node, const std::string& topic) {
  // getBusInfo lists each connection as [id, peer, direction, transport, topic, ...]; the node
  // adds an outbound one once the subscriber's header arrived, when it starts counting it.
  std::optional<XmlRpc::XmlRpcValue> connections = callNodeApi(node, "getBusInfo");
  if (!connections || connections->getType() != XmlRpc::XmlRpcValue::TypeArray) return false;
  for (int i = 0; i < connections->size(); ++i) {
    XmlRpc::XmlRpcValue& connection = (*connections)[i];
    if (connection.getType() != XmlRpc::XmlRpcValue::TypeArray || connection.size() < 5) continue;
    if (static_cast<std::string>(connection[1]) == ros::this_node::getName() &&
        static_cast<std::string>(connection[2]) == "o" &&
        static_cast<std::string>(connection[4]) == topic) {
      return true;
    }
  }
  return false;
}

std::string DiagnosticsWatch::Status::value(const std::string& key) const {
  const auto it = values.find(key);
  return it == values.end() ? std::string() : it->second;
}

uint64_t DiagnosticsWatch::Status::number(const std::string& key) const {
  const std::string text = value(key);
  return text.empty() ? 0 : std::stoull(text);
}

DiagnosticsWatch::DiagnosticsWatch(ros::NodeHandle& nh, const std::string& node)
    : state_(std::make_shared<State>()) {
  state_->prefix = node + ": ";
  sub_ = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100,
      [state = state_](const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
        std::lock_guard<std::mutex> lock(state->mutex);
        for (const auto& status : msg->status) {
          if (status.name.rfind(state->prefix, 0) != 0) continue;
          Status& stored = state->statuses[status.name.substr(state->prefix.size())];
          ++stored.received;
          stored.level = status.level;
          stored.message = status.message;
          stored.values.clear();
          for (const auto& kv : status.values) stored.values[kv.key] = kv.value;
        }
      });
}

DiagnosticsWatch::Status DiagnosticsWatch::latest(const std::string& name) const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  const auto it = state_->statuses.find(name);
  return it == state_->statuses.end() ? Status{} : it->second;
}

std::optional<DiagnosticsWatch::Status> DiagnosticsWatch::waitFor(
    const std::string& name, uint64_t after_count, const std::function<bool(const Status&)>& pred,
    const std::function<bool()>& keep_waiting, double timeout_s) const {
  std::optional<Status> found;
  test_support::waitFor(
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

std::vector<std::string> DiagnosticsWatch::names() const {
  std::lock_guard<std::mutex> lock(state_->mutex);
  std::vector<std::string> result;
  for (const auto& [name, status] : state_->statuses) result.push_back(name);
  return result;
}

int runAllTestsWithSim(const serial_robot_driver::sim::SimOptions& options,
                       serial_robot_driver::sim::RobotSim** robot) {
  serial_robot_driver::sim::RobotSim sim(options);
  sim.start();
  *robot = &sim;
  const int result = RUN_ALL_TESTS();
  *robot = nullptr;
  sim.stop();
  return result;
}

bool setEStopAndWait(ros::Publisher& e_stop, const DiagnosticsWatch& diagnostics, bool engaged,
                     double timeout_s) {
  std_msgs::Bool msg;
  msg.data = engaged;
  e_stop.publish(msg);
  const uint64_t seen = diagnostics.latest("e_stop").received;
  return diagnostics
      .waitFor(
          "e_stop", seen,
          [&](const DiagnosticsWatch::Status& status) { return status.flag("engaged") == engaged; },
          [] { return ros::ok(); }, timeout_s)
      .has_value();
}

}  // namespace test_support
