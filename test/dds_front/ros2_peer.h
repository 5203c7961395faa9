#pragma once
// A ROS 2 machine as the driver's DDS tests see it: a second participant on plain Cyclone (none
// of the driver's wrappers), in a domain of the test's own, discovering by unicast on 127.0.0.1
// with multicast off; it reads what the builtin topics say of the driver's endpoints and reads
// and writes ROS 2 topics with rclcpp's default QoS, written out here.
#include <dds/dds.h>

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "../dds/dds_test_support.h"

namespace dds_test {

struct RawType;

/// One endpoint of another participant, as the builtin topics describe it.
struct SeenEndpoint {
  dds_guid_t guid{};
  dds_guid_t participant{};
  std::string type_name;
  std::string user_data;
  dds_reliability_kind_t reliability = DDS_RELIABILITY_BEST_EFFORT;
  dds_durability_kind_t durability = DDS_DURABILITY_VOLATILE;
  dds_history_kind_t history = DDS_HISTORY_KEEP_ALL;
  int32_t depth = 0;
};

class Ros2Peer {
 public:
  /// Joins `domain` (fails the test on error).
  explicit Ros2Peer(int domain);
  ~Ros2Peer();
  Ros2Peer(const Ros2Peer&) = delete;
  Ros2Peer& operator=(const Ros2Peer&) = delete;

  /// The publication (or subscription) on DDS topic `topic` once discovered (waits up to 30 s).
  std::optional<SeenEndpoint> discover(bool publication, const std::string& topic);
  /// A reader / writer of `type` on `topic`: reliable, keep-last 10, `durability`.
  dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& topic,
                      dds_durability_kind_t durability = DDS_DURABILITY_VOLATILE);
  dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& topic);
  /// A writer of sequence<octet> samples that calls its type `dds_type_name` (a type the driver
  /// reads): peers match on the type name alone, so the driver receives the bytes written as a
  /// sample of its own type, whatever they are (hostile_dds_inputs.h). From a participant of its
  /// own, as the topic has another type here.
  dds_entity_t rawWriter(const std::string& dds_type_name, const std::string& topic);
  /// The participant, for DDS calls the peer does not offer (builtin topics).
  dds_entity_t participant() const { return participant_; }
  /// Whether `writer` matches a reader now (the driver's subscription was discovered).
  static bool matched(dds_entity_t writer);

 private:
  dds_entity_t topic(const dds_topic_descriptor_t& type, const std::string& name);
  int domain_id_ = 0;
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  dds_entity_t raw_participant_ = 0;
  /// The raw writers' type descriptors: they outlive the topics made of them.
  std::vector<std::unique_ptr<RawType>> raw_types_;
};

/// geometry_msgs/Twist samples written by `writer` at about 20 Hz from a thread of its own while
/// this lives (a teleop node).
class TwistStream {
 public:
  TwistStream(dds_entity_t writer, double linear_x);
  ~TwistStream();
  TwistStream(const TwistStream&) = delete;
  TwistStream& operator=(const TwistStream&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// The USER_DATA of `qos` as text ("" when it has none).
std::string userData(const dds_qos_t* qos);

/// Takes every sample `reader` holds, calling `visit` with each valid one.
void takeAll(dds_entity_t reader, const std::function<void(const void* sample)>& visit);

/// Waits until `reader` has received a sample of T that `wanted` accepts.
template <typename T>
bool waitForSample(dds_entity_t reader, const std::function<bool(const T&)>& wanted) {
  bool found = false;
  return waitFor([&] {
    takeAll(reader,
            [&](const void* sample) { found = found || wanted(*static_cast<const T*>(sample)); });
    return found;
  });
}

/// The driver's "driver_node: e_stop" status as `peer` last received it on diagnostics: the
/// e-stop's state and every count of refused inputs.
class EStopStatus {
 public:
  explicit EStopStatus(Ros2Peer& peer);
  /// Waits until `key` counts `expected` (absent: 0); false if it never does.
  bool waitForCount(const std::string& key, uint64_t expected);
  /// `key`'s count in the latest status (waits for the first one).
  uint64_t count(const std::string& key);
  /// `key`'s value in the latest status ("" when absent; waits for the first one).
  std::string value(const std::string& key);

 private:
  void takeAll();
  dds_entity_t reader_;
  std::map<std::string, std::string> values_;
};

/// Writes a std_msgs/Bool (an e_stop); false when DDS refused it.
bool writeBool(dds_entity_t writer, bool data);

}  // namespace dds_test
