#include "serial_robot_driver/ros/wire_capture.h"

#include <ros/serialization.h>
#include <ros/topic_manager.h>

#include <boost/make_shared.hpp>
#include <boost/shared_array.hpp>
#include <typeinfo>
#include <utility>

namespace serial_robot_driver::ros_layer {

/// The deleter of a buffer handed to roscpp: frees the serialized chunk and tells the publishing
/// thread that roscpp has room again (on whichever thread roscpp lets go of it).
struct WireCapture::Release {
  boost::shared_array<uint8_t> buffer;
  std::shared_ptr<Shared> shared;

  void operator()(uint8_t*) {
    buffer.reset();
    {
      std::lock_guard<std::mutex> lock(shared->mutex);
      --shared->in_roscpp;
    }
    shared->wake.notify_all();
  }
};

WireCapture::WireCapture(ros::NodeHandle& nh, const DriverParams& params, WireCaptureLimits limits)
    : stamps_(params), limits_(limits) {
  // roscpp's queue: a backstop, never reached (publishLoop() keeps below it; see the header).
  publisher_ = nh.advertise<serial_robot_driver::SerialChunk>(
      "serial_raw", static_cast<uint32_t>(limits_.max_in_roscpp));
  thread_ = std::thread([this] { publishLoop(); });
}

WireCapture::~WireCapture() {
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    stopping_ = true;
  }
  shared_->wake.notify_all();
  if (thread_.joinable()) thread_.join();
}

void WireCapture::onChunk(const core::WireChunk& chunk) {
  serial_robot_driver::SerialChunk msg;
  msg.header.stamp = stamps_(chunk.time);
  msg.port = chunk.port;
  msg.outbound = chunk.outbound;
  msg.data.assign(chunk.data, chunk.data + chunk.size);
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (queue_.size() >= limits_.max_queued) {
      ++stats_.dropped;
      return;
    }
    queue_.push_back(std::move(msg));
  }
  shared_->wake.notify_all();
}

void WireCapture::publishLoop() {
  std::unique_lock<std::mutex> lock(shared_->mutex);
  while (true) {
    shared_->wake.wait(lock, [this] {
      return stopping_ || (!queue_.empty() && shared_->in_roscpp < limits_.max_in_roscpp);
    });
    if (queue_.empty()) return;  // stopping, and everything is out
    if (shared_->in_roscpp >= limits_.max_in_roscpp) {
      // Stopping while a subscriber keeps roscpp full: waiting for it could last for ever.
      stats_.dropped += queue_.size();
      queue_.clear();
      return;
    }
    const auto msg =
        boost::make_shared<serial_robot_driver::SerialChunk>(std::move(queue_.front()));
    queue_.pop_front();
    lock.unlock();
    publish(msg);  // never under the lock: roscpp may release a buffer (Release) on this thread
    lock.lock();
    ++stats_.chunks;
    stats_.bytes += msg->data.size();
  }
}

void WireCapture::publish(const boost::shared_ptr<serial_robot_driver::SerialChunk>& msg) {
  if (!publisher_) return;  // unadvertised (shutting down): as ros::Publisher::publish does
  // What ros::Publisher::publish(shared_ptr) does, with our own serialization: in-process
  // subscribers get the message itself, and the one serialized buffer every other subscriber's
  // queue shares is counted while it lives.
  ros::SerializedMessage message;
  message.type_info = &typeid(serial_robot_driver::SerialChunk);
  message.message = msg;
  const std::shared_ptr<Shared> shared = shared_;
  ros::TopicManager::instance()->publish(
      publisher_.getTopic(),
      [&msg, &shared]() {
        ros::SerializedMessage serialized = ros::serialization::serializeMessage(*msg);
        {
          std::lock_guard<std::mutex> lock(shared->mutex);
          ++shared->in_roscpp;
        }
        uint8_t* const data = serialized.buf.get();
        serialized.buf = boost::shared_array<uint8_t>(data, Release{serialized.buf, shared});
        return serialized;
      },
      message);
}

WireCaptureStats WireCapture::stats() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  WireCaptureStats copy = stats_;
  copy.queued = queue_.size();
  copy.in_roscpp = shared_->in_roscpp;
  return copy;
}

void WireCapture::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  writeStatusReport(core::wireCaptureStatus(stats()), status);
}

}  // namespace serial_robot_driver::ros_layer
