// Cross-device wiring without naming a device: a device offers a capability of some kind (a
// heading it measures, ...) and another asks for that kind, through a Capabilities board the node
// fills before the links start. The kinds are the classes below; each is one typed interface, so
// nothing is cast at run time but back to the kind it was offered as.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <typeindex>
#include <utility>
#include <vector>

#include "serial_robot_driver/core/serial_link.h"

namespace serial_robot_driver::core {

/// The root of every kind of capability.
class Capability {
 public:
  virtual ~Capability() = default;
};

/// Kind: the robot's heading (yaw, rad, counter-clockwise about z up) as a sensor measures it, e.g.
/// the IMU's yaw for ~base/use_imu_heading.
class HeadingSource : public Capability {
 public:
  /// Called on the measuring device's thread with each heading and its arrival time.
  using Listener = std::function<void(double yaw, Clock::time_point arrival)>;
  /// Before the links start.
  virtual void addHeadingListener(Listener listener) = 0;
  /// How far each heading is to be trusted (rad^2), as the measuring device knows it.
  virtual double yawVariance() const = 0;
};

/// Kind: whether the robot is held still, for a sensor calibrated only then (the gyro bias):
/// "<device>: <why>" for the first thing that may be moving it, "" when nothing is. Any thread.
class MotionQuery : public Capability {
 public:
  virtual std::string motionInForce() const = 0;
  /// Whether motionInForce() would name something, without building its text: cheap enough to
  /// ask once per sensor frame.
  virtual bool inMotion() const { return !motionInForce().empty(); }
};

/// A HeadingSource that hands each heading it is given to its listeners (the measuring device
/// owns one and offers it).
class HeadingFeed : public HeadingSource {
 public:
  /// `yaw_variance`: the measuring device's (rad^2).
  explicit HeadingFeed(double yaw_variance = 0.0) : yaw_variance_(yaw_variance) {}
  double yawVariance() const override { return yaw_variance_; }
  void addHeadingListener(Listener listener) override { listeners_.push_back(std::move(listener)); }
  /// On the measuring device's thread; the listeners were all added before it runs.
  void publish(double yaw, Clock::time_point arrival) const {
    for (const Listener& listener : listeners_) listener(yaw, arrival);
  }
  bool wanted() const { return !listeners_.empty(); }

 private:
  const double yaw_variance_;
  std::vector<Listener> listeners_;
};

/// The capabilities offered in one node, by kind. The first offer of a kind is the one found.
class Capabilities {
 public:
  /// `capability` must outlive every device that asks for it.
  template <typename Kind>
  void offer(Kind& capability) {
    static_assert(std::is_base_of_v<Capability, Kind>, "a kind of capability");
    offered_.emplace(std::type_index(typeid(Kind)), &capability);
  }
  /// The capability of kind `Kind` offered, or null.
  template <typename Kind>
  Kind* find() const {
    static_assert(std::is_base_of_v<Capability, Kind>, "a kind of capability");
    const auto found = offered_.find(std::type_index(typeid(Kind)));
    // Stored under its own kind by offer<Kind>(): this is the type it was offered as.
    return found == offered_.end() ? nullptr : static_cast<Kind*>(found->second);
  }

 private:
  std::map<std::type_index, Capability*> offered_;
};

}  // namespace serial_robot_driver::core
