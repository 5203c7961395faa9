#include "serial_robot_driver/devices/echo/sim/echo_sim.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "serial_robot_driver/devices/echo/echo_codec.h"

namespace serial_robot_driver::devices::echo::sim {

using serial_robot_driver::sim::Clock;
using serial_robot_driver::sim::DeviceSimStats;
using serial_robot_driver::sim::Outbox;
using serial_robot_driver::sim::Outgoing;
using serial_robot_driver::sim::OutputKind;
using serial_robot_driver::sim::PortCounters;
using serial_robot_driver::sim::SimWorld;
using serial_robot_driver::sim::statsLine;
using serial_robot_driver::sim::TimePoint;

const OutputKind kEchoAnswerOutput{"echo_replies", 1};

void EchoSim::handleFrame(const protocol::FrameFamily& family, const uint8_t* data,
                          std::size_t size, TimePoint at, Outbox* out) {
  if (family != kRequestFrames) return;
  const auto payload = decode(kRequestType, data, size);
  if (!payload) return;  // the framer verified it; nothing else can fail
  ++stats_.requests;
  if (latency_ == Clock::duration::zero()) {
    ++stats_.answers;
    out->push_back(Outgoing{&kEchoAnswerOutput, encodeAnswer(*payload)});
    return;
  }
  pending_.emplace_back(at + latency_, encodeAnswer(*payload));
}

void EchoSim::tick(TimePoint now, SimWorld& /*world*/, Outbox* out) {
  while (!pending_.empty() && pending_.front().first <= now) {
    ++stats_.answers;
    out->push_back(Outgoing{&kEchoAnswerOutput, std::move(pending_.front().second)});
    pending_.pop_front();
  }
}

TimePoint EchoSim::nextEvent() const {
  return pending_.empty() ? TimePoint::max() : pending_.front().first;
}

DeviceSimStats EchoSim::stats(const PortCounters& /*ports*/) const {
  return DeviceSimStats{
      "echo",
      stats_,
      {statsLine("echo_requests", stats_.requests), statsLine("echo_answers", stats_.answers)}};
}

}  // namespace serial_robot_driver::devices::echo::sim

namespace serial_robot_driver::devices::echo {

namespace {

std::unique_ptr<serial_robot_driver::sim::SimDevice> makeEchoSim(
    const serial_robot_driver::sim::HostedDeviceOptions& options, uint32_t,
    serial_robot_driver::sim::TimePoint) {
  double latency_ms = 0.0;
  const auto setting = options.settings.find("latency-ms");
  if (setting != options.settings.end()) {
    char* end = nullptr;
    latency_ms = std::strtod(setting->second.c_str(), &end);
    if (setting->second.empty() || *end != '\0' || !std::isfinite(latency_ms) || latency_ms < 0) {
      throw std::invalid_argument("bad value for --echo-latency-ms: '" + setting->second + "'");
    }
  }
  return std::make_unique<sim::EchoSim>(serial_robot_driver::sim::fromSeconds(latency_ms / 1000.0));
}

}  // namespace

// Not one of the robot's own: hosted only when asked for, and no stats unless hosted (no
// left_out_stats).
extern const serial_robot_driver::sim::SimDeviceModule kSimModule{
    .name = "echo",
    .description = "echo device",
    .toggle_help = "simulate the echo device (on the shared pty)",
    .link_help = "own pty for the echo device (hosts it)",
    .seed_offset = 10,  // draws nothing at random; kept apart from the robot's own devices' seeds
    .outputs = {&sim::kEchoAnswerOutput},
    .make = makeEchoSim,
    .options = {{"latency-ms", "MS", "echo answer latency (default 0)", nullptr, nullptr}}};

}  // namespace serial_robot_driver::devices::echo
