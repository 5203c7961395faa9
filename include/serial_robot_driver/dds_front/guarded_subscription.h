// A DDS input of a front end: a subscription whose callback is guarded() under the topic's own
// name, so the name a refusal is counted under is the topic's and is written once.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "serial_robot_driver/core/input_refusals.h"
#include "serial_robot_driver/dds/subscription.h"
#include "serial_robot_driver/dds_front/dds_conversions.h"

namespace serial_robot_driver::dds_front {

/// `callback` on every `topic` sample, on the participant's dispatch thread; an exception it lets
/// out is counted in `counters` as "callback errors: <topic>" and logged (guarded()).
template <typename Message>
std::unique_ptr<dds::Subscription<Message>> subscribeGuarded(
    dds::Participant& participant, core::InputRefusals& counters, const std::string& topic,
    std::function<void(const Message&)> callback) {
  return std::make_unique<dds::Subscription<Message>>(
      participant, topic, guarded<Message>(counters, topic, std::move(callback)));
}

}  // namespace serial_robot_driver::dds_front
