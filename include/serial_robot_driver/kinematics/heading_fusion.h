// The heading of an IMU rigidly mounted on the base, fused into commanded-motion odometry
// (~base/use_imu_heading).
//
// While IMU samples are fresh, odometry's heading is the IMU's yaw relative to an anchor: the IMU
// yaw and odometry heading of the moment fusion (re)started (the last odometry reset, the first
// sample, or the first sample after an outage). Anchoring to where odometry already stands is what
// keeps the heading from jumping when the IMU comes or goes. Without a fresh sample the caller
// integrates the commanded turn on from the last fused heading.
//
// Threading: addSample() runs on the body port's reader thread; everything else is called by the
// base controller with its own lock held (from the 50 Hz loop, the reset service, stats()). The
// newest sample is handed over under sample_mutex_, held only to copy two values, so the reader
// never waits on the base loop or its port writes.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>

namespace serial_robot_driver::kinematics {

using SteadyClock = std::chrono::steady_clock;

/// An IMU sample older than this (or none at all) is stale and odometry falls back to the
/// commanded heading: 0.25 s is 12 periods at the 50 Hz default telemetry rate, long enough to
/// ride out a few lost frames, short enough to stop trusting a board that stopped streaming.
constexpr std::chrono::milliseconds kImuHeadingStaleAfter{250};

/// Where odometry's heading comes from right now.
enum class HeadingSource {
  kWaitingForImu,  ///< fusion on, no IMU sample yet: the commanded heading
  kImu,            ///< the IMU's yaw since the anchor
  kImuStale,       ///< fusion on, the IMU went stale: the commanded heading from the last fused one
};

const char* toString(HeadingSource source);

class HeadingFusion {
 public:
  explicit HeadingFusion(SteadyClock::duration stale_after = kImuHeadingStaleAfter);

  /// Any thread: the IMU's yaw (rad, any range; wrapping is handled) measured at `stamp`. A sample
  /// older than the stored one is ignored.
  void addSample(double imu_yaw, SteadyClock::time_point stamp);

  /// The heading odometry has at `now` (wrapped to [-pi, pi]), or nullopt when no
  /// fresh IMU sample exists and the caller integrates the commanded turn instead. `odom_yaw` is
  /// odometry's heading before this step: a (re)anchor makes it the fused heading's start.
  std::optional<double> heading(SteadyClock::time_point now, double odom_yaw);

  /// Odometry was reset. The next heading() re-anchors, so the fused heading starts
  /// from the reset heading (the IMU's yaw now counts as zero).
  void restart() { anchored_ = false; }

  HeadingSource source() const { return source_; }
  /// Times the IMU went stale after having been fused.
  uint64_t fallbacks() const { return fallbacks_; }
  /// Seconds between `now` and the newest sample's stamp; nullopt before the first sample.
  std::optional<double> sampleAge(SteadyClock::time_point now) const;

 private:
  struct Sample {
    double yaw = 0;
    SteadyClock::time_point stamp;
  };
  std::optional<Sample> latest() const;

  const SteadyClock::duration stale_after_;
  mutable std::mutex sample_mutex_;  // guards newest_ only
  std::optional<Sample> newest_;
  // Guarded by the caller (the base controller's lock).
  bool anchored_ = false;
  double offset_ = 0;  ///< IMU yaw minus odometry heading at the anchor
  HeadingSource source_ = HeadingSource::kWaitingForImu;
  uint64_t fallbacks_ = 0;
};

}  // namespace serial_robot_driver::kinematics
