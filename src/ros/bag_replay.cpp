#include "serial_robot_driver/ros/bag_replay.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sys/stat.h>

#include <algorithm>
#include <sstream>

#include "serial_robot_driver/SerialChunk.h"
#include "serial_robot_driver/core/device_module.h"
#include "serial_robot_driver/ros/conversions.h"

namespace serial_robot_driver::ros_layer {

namespace {

constexpr char kTopicName[] = "serial_raw";

/// "serial_raw" itself or the last name of a namespaced one ("/robot1/serial_raw").
bool isSerialRawTopic(const std::string& topic) {
  const std::size_t slash = topic.rfind('/');
  return topic.substr(slash == std::string::npos ? 0 : slash + 1) == kTopicName;
}

std::string joined(const std::set<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text.empty() ? "none" : text;
}

}  // namespace

Recording readRecording(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) throw ReplayError("replay bag " + path + ": no such file");
  rosbag::Bag bag;
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw ReplayError("replay bag " + path + " cannot be read as a bag: " + e.what());
  }

  Recording recording;
  try {
    rosbag::View everything(bag);
    std::set<std::string> raw_topics, other_topics;
    for (const rosbag::ConnectionInfo* connection : everything.getConnections()) {
      (isSerialRawTopic(connection->topic) ? raw_topics : other_topics).insert(connection->topic);
    }
    if (raw_topics.empty()) {
      throw ReplayError("replay bag " + path +
                        " has no serial_raw topic (record it from a driver running with ~capture: "
                        "true, e.g. record.launch raw:=true); its topics: " +
                        joined(other_topics));
    }
    if (raw_topics.size() > 1) {
      throw ReplayError("replay bag " + path + " has serial_raw of several drivers (" +
                        joined(raw_topics) + "); replay one with a bag filtered to one topic");
    }
    recording.topic = *raw_topics.begin();
    // The recording lasts as long as the bag: a silence on the ports at its end counts too.
    recording.end =
        transport::RecordedStamp(static_cast<int64_t>(everything.getEndTime().toNSec()));
    rosbag::View view(bag, rosbag::TopicQuery(recording.topic));
    for (const rosbag::MessageInstance& message : view) {
      const auto chunk = message.instantiate<serial_robot_driver::SerialChunk>();
      if (!chunk) {
        throw ReplayError("replay bag " + path + ": " + recording.topic + " holds " +
                          message.getDataType() + ", not serial_robot_driver/SerialChunk");
      }
      if (chunk->outbound) {
        ++recording.outbound_chunks;
        continue;
      }
      const transport::RecordedStamp stamp(static_cast<int64_t>(chunk->header.stamp.toNSec()));
      recording.ports[chunk->port].push_back({stamp, chunk->data});
      recording.end = std::max(recording.end, stamp);
    }
  } catch (const rosbag::BagException& e) {
    throw ReplayError("replay bag " + path + " is damaged: " + e.what());
  }
  if (recording.ports.empty()) {
    throw ReplayError("replay bag " + path + ": " + recording.topic +
                      " holds no inbound chunk (nothing the devices sent)");
  }
  return recording;
}

std::set<std::string> configuredPorts(const DriverParams& params) {
  std::set<std::string> ports;
  for (const core::DeviceModule* device : core::registeredDevices()) {
    if (params.enabled(*device)) ports.insert(params.portOf(*device));
  }
  return ports;
}

BagReplay::BagReplay(const DriverParams& params)
    : path_(params.replay_bag), recording_(readRecording(params.replay_bag)) {
  const std::set<std::string> configured = configuredPorts(params);
  transport::RecordedStamp first = transport::RecordedStamp::max();
  for (const auto& [port, chunks] : recording_.ports) {
    if (!configured.count(port)) {
      throw ReplayError("replay bag " + path_ + " has chunks of port " + port +
                        ", which the configuration does not have (configured: " +
                        joined(configured) + "); load the configuration the bag was recorded with");
    }
    first = std::min(first, chunks.front().recorded);
  }
  pacing_ = std::make_shared<transport::ReplayPacing>(params.replay_rate, first, recording_.end);
  for (const std::string& port : configured) {
    auto found = recording_.ports.find(port);
    std::vector<transport::RecordedChunk> chunks;
    if (found != recording_.ports.end()) chunks = found->second;
    ports_[port] = std::make_shared<transport::RecordedPort>(port, std::move(chunks), pacing_);
  }
}

core::SerialLink::StreamFactory BagReplay::streamFactory() const {
  const auto ports = ports_;
  return [ports](const core::SerialLinkOptions& options) -> std::unique_ptr<transport::ByteStream> {
    return std::make_unique<transport::RecordedStream>(ports.at(options.path));
  };
}

bool BagReplay::finished() const {
  return std::all_of(ports_.begin(), ports_.end(),
                     [](const auto& entry) { return entry.second->finished(); });
}

std::string BagReplay::summary() const {
  std::ostringstream text;
  text << "replay of " << path_ << " (" << recording_.topic << "):";
  for (const auto& [name, port] : ports_) {
    const transport::RecordedPortStats s = port->stats();
    text << " port " << name << ": " << s.chunks_fed << " chunks (" << s.bytes_fed
         << " bytes) fed, " << s.reopens << " opens, " << s.writes_discarded << " writes ("
         << s.bytes_discarded << " bytes) discarded;";
  }
  return text.str();
}

}  // namespace serial_robot_driver::ros_layer
