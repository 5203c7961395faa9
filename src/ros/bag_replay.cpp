#include "serial_robot_driver/ros/bag_replay.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sys/stat.h>

#include <set>

#include "serial_robot_driver/SerialChunk.h"

namespace serial_robot_driver::ros_layer {

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
    std::set<std::string> topics;
    for (const rosbag::ConnectionInfo* connection : everything.getConnections()) {
      topics.insert(connection->topic);
    }
    recording.topic = core::serialRawTopic(path, topics);
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
      core::addRecordedChunk(
          recording, chunk->port, chunk->outbound,
          transport::RecordedStamp(static_cast<int64_t>(chunk->header.stamp.toNSec())),
          chunk->data);
    }
  } catch (const rosbag::BagException& e) {
    throw ReplayError("replay bag " + path + " is damaged: " + e.what());
  }
  core::requireInboundChunks(path, recording);
  return recording;
}

}  // namespace serial_robot_driver::ros_layer
