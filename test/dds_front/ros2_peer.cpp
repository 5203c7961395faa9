#include "ros2_peer.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "../dds/loopback_observer_config.h"
#include "serial_robot_driver/dds/messages.h"

namespace dds_test {

std::string userData(const dds_qos_t* qos) {
  void* data = nullptr;
  size_t size = 0;
  if (!qos || !dds_qget_userdata(qos, &data, &size) || !data) return "";
  std::string text(static_cast<const char*>(data), size);
  dds_free(data);
  return text;
}

namespace {

SeenEndpoint seen(const dds_builtintopic_endpoint_t& endpoint) {
  SeenEndpoint out;
  out.guid = endpoint.key;
  out.participant = endpoint.participant_key;
  out.type_name = endpoint.type_name;
  out.user_data = userData(endpoint.qos);
  dds_qget_reliability(endpoint.qos, &out.reliability, nullptr);
  dds_qget_durability(endpoint.qos, &out.durability);
  dds_qget_history(endpoint.qos, &out.history, &out.depth);
  return out;
}

dds_qos_t* ros2Qos(dds_durability_kind_t durability) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, durability);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  return qos;
}

}  // namespace

bool writeBool(dds_entity_t writer, bool data) {
  std_msgs_msg_dds__Bool_ msg{data};
  return dds_write(writer, &msg) == DDS_RETCODE_OK;
}

/// struct { sequence<octet> bytes; } under another type's name.
struct RawType {
  explicit RawType(const std::string& type_name)
      : name(type_name),
        descriptor{.m_size = sizeof(dds_sequence_string),  // {max, length, buffer, release}
                   .m_align = alignof(dds_sequence_string),
                   .m_flagset = 0,
                   .m_nkeys = 0,
                   .m_typename = name.c_str(),
                   .m_keys = nullptr,
                   .m_nops = 2,
                   .m_ops = kOps,
                   .m_meta = "",
                   .type_information = {},
                   .type_mapping = {},
                   .restrict_data_representation = 0} {}
  static constexpr uint32_t kOps[] = {DDS_OP_ADR | DDS_OP_TYPE_SEQ | DDS_OP_SUBTYPE_1BY, 0,
                                      DDS_OP_RTS};
  const std::string name;
  const dds_topic_descriptor_t descriptor;
};

Ros2Peer::Ros2Peer(int domain) : domain_id_(domain) {
  domain_ = dds_create_domain(domain, dds_test::kLoopbackObserverConfig);
  EXPECT_GT(domain_, 0) << dds_strretcode(domain_);
  participant_ = dds_create_participant(domain, nullptr, nullptr);
  EXPECT_GT(participant_, 0) << dds_strretcode(participant_);
}

Ros2Peer::~Ros2Peer() {
  if (domain_ > 0) dds_delete(domain_);
}

std::optional<SeenEndpoint> Ros2Peer::discover(bool publication, const std::string& topic) {
  const dds_entity_t reader = dds_create_reader(
      participant_,
      publication ? DDS_BUILTIN_TOPIC_DCPSPUBLICATION : DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr,
      nullptr);
  std::optional<SeenEndpoint> found;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!found && std::chrono::steady_clock::now() < give_up) {
    takeAll(reader, [&](const void* sample) {
      const auto* endpoint = static_cast<const dds_builtintopic_endpoint_t*>(sample);
      if (topic == endpoint->topic_name) found = seen(*endpoint);
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  dds_delete(reader);
  return found;
}

dds_entity_t Ros2Peer::topic(const dds_topic_descriptor_t& type, const std::string& name) {
  const dds_entity_t topic = dds_create_topic(participant_, &type, name.c_str(), nullptr, nullptr);
  EXPECT_GT(topic, 0) << name << ": " << dds_strretcode(topic);
  return topic;
}

dds_entity_t Ros2Peer::reader(const dds_topic_descriptor_t& type, const std::string& name,
                              dds_durability_kind_t durability) {
  dds_qos_t* qos = ros2Qos(durability);
  const dds_entity_t reader = dds_create_reader(participant_, topic(type, name), qos, nullptr);
  dds_delete_qos(qos);
  EXPECT_GT(reader, 0) << name;
  return reader;
}

dds_entity_t Ros2Peer::writer(const dds_topic_descriptor_t& type, const std::string& name) {
  dds_qos_t* qos = ros2Qos(DDS_DURABILITY_VOLATILE);
  const dds_entity_t writer = dds_create_writer(participant_, topic(type, name), qos, nullptr);
  dds_delete_qos(qos);
  EXPECT_GT(writer, 0) << name;
  return writer;
}

dds_entity_t Ros2Peer::rawWriter(const std::string& dds_type_name, const std::string& name) {
  if (raw_participant_ <= 0) {
    raw_participant_ = dds_create_participant(domain_id_, nullptr, nullptr);
    EXPECT_GT(raw_participant_, 0) << dds_strretcode(raw_participant_);
  }
  raw_types_.push_back(std::make_unique<RawType>(dds_type_name));
  const dds_entity_t topic = dds_create_topic(raw_participant_, &raw_types_.back()->descriptor,
                                              name.c_str(), nullptr, nullptr);
  EXPECT_GT(topic, 0) << name << ": " << dds_strretcode(topic);
  dds_qos_t* qos = ros2Qos(DDS_DURABILITY_VOLATILE);
  const dds_entity_t writer = dds_create_writer(raw_participant_, topic, qos, nullptr);
  dds_delete_qos(qos);
  EXPECT_GT(writer, 0) << name;
  return writer;
}

bool Ros2Peer::matched(dds_entity_t writer) {
  dds_publication_matched_status_t status{};
  return dds_get_publication_matched_status(writer, &status) == DDS_RETCODE_OK &&
         status.current_count > 0;
}

TwistStream::TwistStream(dds_entity_t writer, double linear_x) {
  thread_ = std::thread([this, writer, linear_x] {
    geometry_msgs_msg_dds__Twist_ twist{};
    twist.linear.x = linear_x;
    while (!stop_) {
      dds_write(writer, &twist);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
}

TwistStream::~TwistStream() {
  stop_ = true;
  thread_.join();
}

EStopStatus::EStopStatus(Ros2Peer& peer)
    : reader_(peer.reader(diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics")) {}

bool EStopStatus::waitForCount(const std::string& key, uint64_t expected) {
  return waitFor([&] { return count(key) == expected; });
}

uint64_t EStopStatus::count(const std::string& key) {
  const std::string text = value(key);
  return text.empty() ? 0 : std::stoull(text);
}

std::string EStopStatus::value(const std::string& key) {
  waitFor([&] {
    takeAll();
    return !values_.empty();
  });
  const auto found = values_.find(key);
  return found == values_.end() ? "" : found->second;
}

void EStopStatus::takeAll() {
  dds_test::takeAll(reader_, [&](const void* sample) {
    const auto& array = *static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(sample);
    for (uint32_t i = 0; i < array.status._length; ++i) {
      const auto& status = array.status._buffer[i];
      if (std::string(status.name) != "driver_node: e_stop") continue;
      values_.clear();
      for (uint32_t j = 0; j < status.values._length; ++j) {
        values_[status.values._buffer[j].key] = status.values._buffer[j].value;
      }
    }
  });
}

void takeAll(dds_entity_t reader, const std::function<void(const void* sample)>& visit) {
  void* samples[32] = {nullptr};
  dds_sample_info_t infos[32];
  dds_return_t count;
  while ((count = dds_take(reader, samples, infos, 32, 32)) > 0) {
    for (dds_return_t i = 0; i < count; ++i) {
      if (infos[i].valid_data) visit(samples[i]);
    }
    dds_return_loan(reader, samples, count);
    samples[0] = nullptr;  // the next take lends again
  }
}

}  // namespace dds_test
