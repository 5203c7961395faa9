#include "serial_robot_driver/core/recording_replay.h"

#include <algorithm>
#include <sstream>
#include <utility>

#include "serial_robot_driver/core/device_module.h"

namespace serial_robot_driver::core {

namespace {

constexpr char kTopicName[] = "serial_raw";

std::string joined(const std::set<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text.empty() ? "none" : text;
}

}  // namespace

void addRecordedChunk(Recording& recording, const std::string& port, bool outbound,
                      transport::RecordedStamp stamp, std::vector<uint8_t> data) {
  if (outbound) {
    ++recording.outbound_chunks;
    return;
  }
  recording.ports[port].push_back({stamp, std::move(data)});
  recording.end = std::max(recording.end, stamp);
}

bool isSerialRawTopic(const std::string& topic) {
  const std::size_t slash = topic.rfind('/');
  return topic.substr(slash == std::string::npos ? 0 : slash + 1) == kTopicName;
}

std::string serialRawTopic(const std::string& path, const std::set<std::string>& topics) {
  std::set<std::string> raw_topics, other_topics;
  for (const std::string& topic : topics) {
    (isSerialRawTopic(topic) ? raw_topics : other_topics).insert(topic);
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
  return *raw_topics.begin();
}

void requireInboundChunks(const std::string& path, const Recording& recording) {
  const bool inbound = std::any_of(recording.ports.begin(), recording.ports.end(),
                                   [](const auto& port) { return !port.second.empty(); });
  if (!inbound) {
    throw ReplayError("replay bag " + path + ": " + recording.topic +
                      " holds no inbound chunk (nothing the devices sent)");
  }
}

std::set<std::string> configuredPorts(const params::DriverParams& params) {
  std::set<std::string> ports;
  for (const DeviceModule* device : registeredDevices()) {
    if (params.enabled(*device)) ports.insert(params.portOf(*device));
  }
  return ports;
}

RecordingReplay::RecordingReplay(std::string path, Recording recording,
                                 const params::DriverParams& params)
    : path_(std::move(path)), recording_(std::move(recording)) {
  requireInboundChunks(path_, recording_);
  const std::set<std::string> configured = configuredPorts(params);
  transport::RecordedStamp first = transport::RecordedStamp::max();
  for (const auto& [port, chunks] : recording_.ports) {
    if (!configured.count(port)) {
      throw ReplayError("replay bag " + path_ + " has chunks of port " + port +
                        ", which the configuration does not have (configured: " +
                        joined(configured) + "); load the configuration the bag was recorded with");
    }
    if (!chunks.empty()) first = std::min(first, chunks.front().recorded);
  }
  pacing_ = std::make_shared<transport::ReplayPacing>(params.replay_rate, first, recording_.end);
  for (const std::string& port : configured) {
    auto found = recording_.ports.find(port);
    std::vector<transport::RecordedChunk> chunks;
    if (found != recording_.ports.end()) chunks = found->second;
    ports_[port] = std::make_shared<transport::RecordedPort>(port, std::move(chunks), pacing_);
  }
}

void RecordingReplay::standIn(params::DriverParams& params,
                              SerialLink::StreamFactory& stream_factory) const {
  stream_factory = streamFactory();
  params.replay_timeline = timeline();
  params.reconnect_interval = 0.0;
}

SerialLink::StreamFactory RecordingReplay::streamFactory() const {
  const auto ports = ports_;
  return [ports](const SerialLinkOptions& options) -> std::unique_ptr<transport::ByteStream> {
    return std::make_unique<transport::RecordedStream>(ports.at(options.path));
  };
}

bool RecordingReplay::finished() const {
  return std::all_of(ports_.begin(), ports_.end(),
                     [](const auto& entry) { return entry.second->finished(); });
}

std::string RecordingReplay::summary() const {
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

std::string replayPaceText(double rate) {
  return rate > 0 ? std::to_string(rate) + "x the recorded pace" : "full speed";
}

}  // namespace serial_robot_driver::core
