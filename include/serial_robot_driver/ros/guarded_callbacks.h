// The last line between an input and roscpp: the core's guard (core/guarded_call.h: counted,
// logged, a service answered as a failure) around every subscription, service and action callback
// of the node, its errors in the ROS log (throttled). An exception never unwinds into roscpp, where
// it would end the process (in a nodelet, the whole manager).
#pragma once

#include <ros/ros.h>

#include <boost/function.hpp>
#include <boost/shared_ptr.hpp>
#include <cstdint>
#include <functional>
#include <string>

#include "serial_robot_driver/core/guarded_call.h"
#include "serial_robot_driver/core/input_refusals.h"

namespace serial_robot_driver::ros_layer {

/// Runs `callback` of `source` (a topic, service or action name). An exception it throws
/// is logged (ROS_ERROR, at most once a second), counted (counters.failed(source)) and swallowed;
/// `error` (may be null) gets its text. Returns whether `callback` returned normally.
bool runGuarded(core::InputRefusals& counters, const std::string& source,
                const std::function<void()>& callback, std::string* error = nullptr);
/// An error runGuarded() caught, as ROS_ERROR (at most once a second: a sender repeating the
/// message must not flood the log; the count is exact).
void logCallbackError(const std::string& line);

using core::answerFailure;

template <typename Message>
using SubscriberCallback = boost::function<void(const boost::shared_ptr<const Message>&)>;

/// `callback`, run through runGuarded() as a callback of `source`.
template <typename Message>
SubscriberCallback<Message> guardedSubscriber(core::InputRefusals& counters,
                                              const std::string& source,
                                              SubscriberCallback<Message> callback) {
  return [&counters, source, callback](const boost::shared_ptr<const Message>& msg) {
    runGuarded(counters, source, [&] { callback(msg); });
  };
}

/// nh.subscribe() of `owner`'s member `callback`, guarded (the topic names the source).
template <typename Message, typename Owner>
ros::Subscriber subscribeGuarded(ros::NodeHandle& nh, core::InputRefusals& counters,
                                 const std::string& topic, uint32_t queue_size,
                                 void (Owner::*callback)(const boost::shared_ptr<const Message>&),
                                 Owner* owner,
                                 const ros::TransportHints& hints = ros::TransportHints()) {
  const SubscriberCallback<Message> bound =
      [callback, owner](const boost::shared_ptr<const Message>& msg) { (owner->*callback)(msg); };
  return nh.subscribe<Message>(topic, queue_size, guardedSubscriber(counters, topic, bound),
                               ros::VoidConstPtr(), hints);
}

/// `serve`, guarded: an exception is answered as a failure ("internal error: ..."), and the call
/// returns true so the caller reads that message instead of a bare "service call failed".
template <typename Request, typename Response>
boost::function<bool(Request&, Response&)> guardedService(
    core::InputRefusals& counters, const std::string& service,
    boost::function<bool(Request&, Response&)> serve) {
  return [&counters, service, serve](Request& req, Response& res) {
    return core::serveGuarded(
        counters, service, res, [&] { return serve(req, res); }, logCallbackError);
  };
}

/// nh.advertiseService() of `owner`'s member `serve`, guarded (the service names the source).
template <typename Owner, typename Request, typename Response>
ros::ServiceServer advertiseGuarded(ros::NodeHandle& nh, core::InputRefusals& counters,
                                    const std::string& service,
                                    bool (Owner::*serve)(Request&, Response&), Owner* owner) {
  const boost::function<bool(Request&, Response&)> bound =
      [serve, owner](Request& req, Response& res) { return (owner->*serve)(req, res); };
  return nh.advertiseService<Request, Response>(
      service, guardedService<Request, Response>(counters, service, bound));
}

}  // namespace serial_robot_driver::ros_layer
