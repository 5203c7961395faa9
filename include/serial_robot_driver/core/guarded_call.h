// The last line between an input and a front end's middleware, ROS-free: every subscription,
// service and action callback of a front end runs through runGuarded(). An exception it lets out
// (a bug, or an input no check foresaw) is logged (the front end's log, which throttles it),
// counted as a "callback error" of its source (InputRefusals, shown in the diagnostics) and, for
// a service, answered as a failure. It never unwinds into the middleware, where it would end the
// process. Inputs are still checked first, where they arrive; this only catches what a check
// missed.
#pragma once

#include <exception>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>

#include "serial_robot_driver/core/input_refusals.h"

namespace serial_robot_driver::core {

/// Where runGuarded() reports an error it caught: one line for the log (may be empty).
using CallbackErrorLog = std::function<void(const std::string& line)>;

/// Runs `callback` of `source` (a topic, service or action name). An exception it throws is
/// counted (counters.failed(source)), logged through `log` and swallowed; `error` (may be null)
/// gets its text. Returns whether `callback` returned normally.
bool runGuarded(InputRefusals& counters, const std::string& source,
                const std::function<void()>& callback, std::string* error,
                const CallbackErrorLog& log);

/// The message a request that ended in the error `what` is answered with.
std::string internalErrorText(const std::string& what);

/// runGuarded()'s rule for the threads that own a port or the base loop, per frame or tick: runs
/// `call`; what it throws goes to `note(what)` instead of up the thread, and no std::function is
/// built for it.
template <typename Call, typename Note>
void catchAll(const Call& call, const Note& note) {
  try {
    call();
  } catch (const std::exception& e) {
    note(e.what());
  } catch (...) {
    note("an exception that is not a std::exception");
  }
}

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

/// Serves a request of `service` with `serve` (which fills `res`, returns whether it answered),
/// guarded: an exception is answered as a failure (internalErrorText()), and the call returns
/// true so the caller reads that message instead of a bare "service call failed".
template <typename Response>
bool serveGuarded(InputRefusals& counters, const std::string& service, Response& res,
                  const std::function<bool()>& serve, const CallbackErrorLog& log) {
  bool answered = true;
  std::string error;
  if (runGuarded(
          counters, service, [&] { answered = serve(); }, &error, log)) {
    return answered;
  }
  answerFailure(res, internalErrorText(error));
  return true;
}

}  // namespace serial_robot_driver::core
