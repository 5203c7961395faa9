// A message published as a shared pointer, so that a subscriber in the same nodelet manager gets
// this very message rather than a serialized copy, and reused for the next publish once nobody else
// holds it: at a hundred frames per second it is then allocated once, not once per frame.
#pragma once

#include <boost/make_shared.hpp>
#include <boost/shared_ptr.hpp>

namespace serial_robot_driver::ros_layer {

template <typename Message>
class ReusedMessage {
 public:
  /// The message to fill and publish next: the last one when nobody else holds it any more (roscpp
  /// lets go of it once serialized; an in-process subscriber keeps it until it is done), otherwise
  /// a new one. Its fields hold what they held last (capacity included): fill each of them.
  Message& next() {
    // use_count() reads with acquire ordering: the other holders' last reads happened before.
    renewed_ = !message_ || message_.use_count() != 1;
    if (renewed_) message_ = boost::make_shared<Message>();
    return *message_;
  }
  /// Whether the last next() gave a new message rather than the one filled before it: a field that
  /// is the same every time need only be filled in a new one.
  bool renewed() const { return renewed_; }
  /// What next() returned, to publish.
  const boost::shared_ptr<Message>& get() const { return message_; }

 private:
  boost::shared_ptr<Message> message_;
  bool renewed_ = true;
};

}  // namespace serial_robot_driver::ros_layer
