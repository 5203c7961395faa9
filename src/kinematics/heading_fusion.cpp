#include "serial_robot_driver/kinematics/heading_fusion.h"

#include <cmath>

namespace serial_robot_driver::kinematics {

const char* toString(HeadingSource source) {
  switch (source) {
    case HeadingSource::kWaitingForImu:
      return "commanded (no IMU yaw yet)";
    case HeadingSource::kImu:
      return "IMU";
    case HeadingSource::kImuStale:
      return "commanded (IMU yaw stale)";
  }
  return "unknown";
}

HeadingFusion::HeadingFusion(SteadyClock::duration stale_after) : stale_after_(stale_after) {}

void HeadingFusion::addSample(double imu_yaw, SteadyClock::time_point stamp) {
  if (!std::isfinite(imu_yaw)) return;
  std::lock_guard<std::mutex> lock(sample_mutex_);
  if (newest_ && stamp < newest_->stamp) return;
  newest_ = Sample{imu_yaw, stamp};
}

std::optional<HeadingFusion::Sample> HeadingFusion::latest() const {
  std::lock_guard<std::mutex> lock(sample_mutex_);
  return newest_;
}

std::optional<double> HeadingFusion::sampleAge(SteadyClock::time_point now) const {
  const std::optional<Sample> sample = latest();
  if (!sample) return std::nullopt;
  return std::chrono::duration<double>(now - sample->stamp).count();
}

std::optional<double> HeadingFusion::heading(SteadyClock::time_point now, double odom_yaw) {
  const std::optional<Sample> sample = latest();
  // A stamp "after" now is a sample that arrived while the caller read its clock: fresh.
  const bool fresh = sample && now - sample->stamp <= stale_after_;
  if (!fresh) {
    if (source_ == HeadingSource::kImu) {
      source_ = HeadingSource::kImuStale;
      ++fallbacks_;
    }
    anchored_ = false;  // whenever the IMU returns, it starts from where odometry stands then
    return std::nullopt;
  }
  if (!anchored_) {
    offset_ = sample->yaw - odom_yaw;
    anchored_ = true;
  }
  source_ = HeadingSource::kImu;
  return std::remainder(sample->yaw - offset_, 2.0 * M_PI);
}

}  // namespace serial_robot_driver::kinematics
