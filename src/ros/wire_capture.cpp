#include "serial_robot_driver/ros/wire_capture.h"

#include <ros/serialization.h>
#include <ros/topic_manager.h>

#include <boost/make_shared.hpp>
#include <boost/shared_array.hpp>
#include <memory>
#include <typeinfo>
#include <utility>

namespace serial_robot_driver::ros_layer {

/// The deleter of a buffer handed to roscpp: frees the serialized chunk and releases its in-flight
/// token, so the queue's thread may publish again (on whichever thread roscpp lets go of it).
struct WireCapture::Release {
  boost::shared_array<uint8_t> buffer;
  std::shared_ptr<void> in_flight;

  void operator()(uint8_t*) {
    buffer.reset();
    in_flight.reset();
  }
};

WireCapture::WireCapture(ros::NodeHandle& nh, const DriverParams& params, WireCaptureLimits limits)
    : stamps_(params),
      // roscpp's queue: a backstop, never reached (the capture queue keeps below it).
      publisher_(nh.advertise<serial_robot_driver::SerialChunk>(
          "serial_raw", static_cast<uint32_t>(limits.max_in_roscpp))),
      queue_(core::CaptureQueueLimits{limits.max_queued, limits.max_in_roscpp}) {}

WireCapture::~WireCapture() { queue_.stop(); }

void WireCapture::onChunk(const core::WireChunk& chunk) {
  serial_robot_driver::SerialChunk msg;
  msg.header.stamp = stamps_(chunk.time);
  msg.port = chunk.port;
  msg.outbound = chunk.outbound;
  msg.data.assign(chunk.data, chunk.data + chunk.size);
  queue_.push([this, msg = std::move(msg)]() mutable {
    return publish(boost::make_shared<serial_robot_driver::SerialChunk>(std::move(msg)));
  });
}

std::size_t WireCapture::publish(const boost::shared_ptr<serial_robot_driver::SerialChunk>& msg) {
  if (!publisher_) return msg->data.size();  // unadvertised (shutting down): as publish() does
  // What ros::Publisher::publish(shared_ptr) does, with our own serialization: in-process
  // subscribers get the message itself, and the one serialized buffer every other subscriber's
  // queue shares holds an in-flight token while it lives.
  ros::SerializedMessage message;
  message.type_info = &typeid(serial_robot_driver::SerialChunk);
  message.message = msg;
  ros::TopicManager::instance()->publish(
      publisher_.getTopic(),
      [this, &msg]() {
        ros::SerializedMessage serialized = ros::serialization::serializeMessage(*msg);
        uint8_t* const data = serialized.buf.get();
        serialized.buf =
            boost::shared_array<uint8_t>(data, Release{serialized.buf, queue_.holdInFlight()});
        return serialized;
      },
      message);
  return msg->data.size();
}

WireCaptureStats WireCapture::stats() const { return queue_.stats(); }

void WireCapture::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  writeStatusReport(core::wireCaptureStatus(stats()), status);
}

}  // namespace serial_robot_driver::ros_layer
