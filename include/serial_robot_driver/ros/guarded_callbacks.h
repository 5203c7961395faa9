// The last line between an input and roscpp. Every subscription, service and action callback of
// the node runs through runGuarded(): an exception it lets out (a bug, or an input no check
// foresaw) is logged (throttled), counted as a "callback error" of its source
// (device::InputRefusals, shown in /diagnostics) and, for a service, answered as a failure. It
// never unwinds into roscpp, where it would end the process (in a nodelet, the whole manager).
// Inputs are still checked first, where they arrive; this only catches what a check missed.
#pragma once

#include <ros/ros.h>

#include <boost/function.hpp>
#include <boost/shared_ptr.hpp>
#include <cstdint>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>

#include "serial_robot_driver/core/input_refusals.h"

namespace serial_robot_driver::ros_layer {

/// Runs `callback` of `source` (a topic, service or action name). An exception it throws
/// is logged (ROS_ERROR, at most once a second), counted (counters.failed(source)) and swallowed;
/// `error` (may be null) gets its text. Returns whether `callback` returned normally.
bool runGuarded(core::InputRefusals& counters, const std::string& source,
                const std::function<void()>& callback, std::string* error = nullptr);

namespace detail {
template <typename T, typename = void>
struct HasSuccess : std::false_type {};
template <typename T>
struct HasSuccess<T, std::void_t<decltype(std::declval<T&>().success)>> : std::true_type {};
template <typename T, typename = void>
struct HasOnline : std::false_type {};
template <typename T>
struct HasOnline<T, std::void_t<decltype(std::declval<T&>().online)>> : std::true_type {};
template <typename T, typename = void>
struct HasMessage : std::false_type {};
template <typename T>
struct HasMessage<T, std::void_t<decltype(std::declval<T&>().message)>> : std::true_type {};
}  // namespace detail

/// The answer to a request that failed: every field at its default, `success` (or servo/ping's
/// `online`) false and `message` set, for those of these fields the response has.
template <typename Response>
void answerFailure(Response& res, const std::string& message) {
  res = Response();
  if constexpr (detail::HasSuccess<Response>::value) res.success = false;
  if constexpr (detail::HasOnline<Response>::value) res.online = false;
  if constexpr (detail::HasMessage<Response>::value) res.message = message;
}

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
    bool answered = true;
    std::string error;
    if (runGuarded(
            counters, service, [&] { answered = serve(req, res); }, &error)) {
      return answered;
    }
    answerFailure(res, "internal error: " + error);
    return true;
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
