// Work nobody asked for is not done: a message for a topic nobody subscribes to is not built. Every
// publishing site of the adapters asks this first (subscribers in the same nodelet manager count).
#pragma once

#include <ros/node_handle.h>
#include <ros/publication.h>
#include <ros/publisher.h>
#include <ros/topic_manager.h>

#include <atomic>
#include <memory>
#include <string>

namespace serial_robot_driver::ros_layer {

/// Whether `publisher` has a subscriber now (false for one not advertised).
inline bool wanted(const ros::Publisher& publisher) {
  return publisher && publisher.getNumSubscribers() > 0;
}

/// A publisher that counts its subscribers itself, from roscpp's connect and disconnect callbacks
/// (run on its NodeHandle's callback queue): asking wanted() on every frame then takes no topic
/// lookup by name under roscpp's topic lock, as ros::Publisher::getNumSubscribers() does.
class CountedPublisher : public ros::Publisher {
 public:
  CountedPublisher() = default;
  CountedPublisher(ros::Publisher publisher, std::shared_ptr<const std::atomic<int>> count)
      : ros::Publisher(std::move(publisher)),
        count_(std::move(count)),
        // The topic's publication, kept while this publisher advertises it: asked directly, it
        // answers without the search by name through every advertised topic.
        publication_(*this ? ros::TopicManager::instance()->lookupPublication(getTopic())
                           : ros::PublicationPtr()) {}
  /// Subscribers counted so far (0 until the callback of the first one ran).
  int counted() const { return count_ ? count_->load(std::memory_order_relaxed) : 0; }
  /// Subscribers connected now, as roscpp knows them (a callback may not have counted them yet).
  bool connected() const {
    if (!*this) return false;  // not advertised (any more)
    return publication_ ? publication_->getNumSubscribers() > 0 : getNumSubscribers() > 0;
  }

 private:
  std::shared_ptr<const std::atomic<int>> count_;
  ros::PublicationPtr publication_;
};

/// nh.advertise<Message>(topic, queue_size), counting its subscribers.
template <typename Message>
CountedPublisher advertiseCounted(ros::NodeHandle& nh, const std::string& topic,
                                  uint32_t queue_size) {
  auto count = std::make_shared<std::atomic<int>>(0);
  ros::AdvertiseOptions options = ros::AdvertiseOptions::create<Message>(
      topic, queue_size, [count](const ros::SingleSubscriberPublisher&) { ++*count; },
      [count](const ros::SingleSubscriberPublisher&) { --*count; }, ros::VoidConstPtr(), nullptr);
  return CountedPublisher(nh.advertise(options), count);
}

/// wanted() without the lookup while the count says yes; a subscriber whose callback has not run
/// yet is still seen (roscpp is asked when the count is 0), so none misses a message.
inline bool wanted(const CountedPublisher& publisher) {
  return publisher.counted() > 0 || publisher.connected();
}

}  // namespace serial_robot_driver::ros_layer
