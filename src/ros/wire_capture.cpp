#include "serial_robot_driver/ros/wire_capture.h"

namespace serial_robot_driver::ros_layer {

WireCapture::WireCapture(ros::NodeHandle& nh, const DriverParams& params) : stamps_(params) {
  // Unbounded roscpp queue: the bound that matters is ours (kMaxQueued), and it is counted.
  publisher_ = nh.advertise<serial_robot_driver::SerialChunk>("serial_raw", 0);
  thread_ = std::thread([this] { publishLoop(); });
}

WireCapture::~WireCapture() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void WireCapture::onChunk(const device::WireChunk& chunk) {
  serial_robot_driver::SerialChunk msg;
  msg.header.stamp = stamps_(chunk.time);
  msg.port = chunk.port;
  msg.outbound = chunk.outbound;
  msg.data.assign(chunk.data, chunk.data + chunk.size);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.size() >= kMaxQueued) {
      ++stats_.dropped;
      return;
    }
    queue_.push_back(std::move(msg));
  }
  wake_.notify_one();
}

void WireCapture::publishLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and everything is out
    serial_robot_driver::SerialChunk msg = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    publisher_.publish(msg);
    lock.lock();
    ++stats_.chunks;
    stats_.bytes += msg.data.size();
  }
}

WireCaptureStats WireCapture::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  WireCaptureStats copy = stats_;
  copy.queued = queue_.size();
  return copy;
}

void WireCapture::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  const WireCaptureStats s = stats();
  if (s.dropped > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "chunks dropped: the publisher fell behind");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "capturing on serial_raw");
  }
  status.add("chunks published", s.chunks);
  status.add("bytes published", s.bytes);
  status.add("chunks dropped", s.dropped);
  status.add("chunks queued", s.queued);
}

}  // namespace serial_robot_driver::ros_layer
